"""Every file reader against mutated valid files (hypothesis): the numbers the file holds or a
GoniometerError that names the file, never another exception, never a hang, never a runaway
allocation.

Each seed is a small valid file of one format; hypothesis applies a few mutations (byte flips,
insertions of troublesome tokens, deletions, truncations, duplicated spans, replaced words, a
value appended to a line, a line dropped or repeated) and the reader must either return sound
data or refuse with a message naming the file. Sound means exactly what an independent oracle
(mesh_oracle.py) reads: a plain-Python parser that takes text formats one line at a time and
binary ones one record at a time with ``struct`` (so a value too many can no longer shift the
numbers that follow it unnoticed). Every call runs under an alarm (a hang fails the test), its
peak allocation is traced (more than 64 MiB for a few-kB file fails it) and the process's address
space is capped (so a forged size fails before it can exhaust the machine).
"""

from __future__ import annotations

import contextlib
import math
import os
import resource
import signal
import struct
import tempfile
import tracemalloc
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from mesh_oracle import assert_reads_like_the_oracle

from vg_addon import GoniometerError
from vg_addon.formats import csvio, meshio

pytestmark = pytest.mark.skipif(
    not hasattr(signal, "SIGALRM") or not hasattr(resource, "RLIMIT_AS"),
    reason="needs POSIX alarms and address-space limits",
)

SECONDS_PER_CALL = 5  # a reader takes milliseconds on these few-kB files
PEAK_BYTES = 64 << 20  # memory a call may allocate at its peak (the inputs are a few kB)
# Address space a call may add: a safety net that stops a forged size before it reaches the
# machine's memory (an allocator that reuses address space it already holds can slip under
# it, so the peak above, traced by tracemalloc, is the bound the test checks).
EXTRA_ADDRESS_SPACE = 1 << 30

# A small mesh: a quad-topped tetrahedron-like solid with a quad face, so readers see both
# triangles and polygons.
POINTS = np.array(
    [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0.5, 0.5, 1.25], [0.5, -0.75, 0.5]],
    dtype=np.float64,
)
TRIANGLES = [[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4], [0, 5, 1]]
QUAD = [0, 3, 2, 1]


def ply_ascii() -> bytes:
    head = [
        "ply",
        "format ascii 1.0",
        "comment fuzz seed",
        f"element vertex {len(POINTS)}",
        "property float x",
        "property float y",
        "property float z",
        "property float nx",
        "property float ny",
        "property float nz",
        f"element face {len(TRIANGLES) + 1}",
        "property list uchar int vertex_indices",
        "end_header",
    ]
    body = [" ".join(f"{v:g}" for v in (*p, 0.0, 0.0, 1.0)) for p in POINTS]
    body += [" ".join(map(str, [len(f), *f])) for f in [*TRIANGLES, QUAD]]
    return ("\n".join(head + body) + "\n").encode()


def ply_binary(order: str, coord: str) -> bytes:
    endian = "<" if order == "little" else ">"
    fmt = {"float": "f", "double": "d"}[coord]
    head = (
        f"ply\nformat binary_{order}_endian 1.0\nelement vertex {len(POINTS)}\n"
        f"property {coord} x\nproperty {coord} y\nproperty {coord} z\n"
        f"element face {len(TRIANGLES) + 1}\nproperty list uchar uint vertex_indices\n"
        "element extra 1\nproperty short flag\nend_header\n"
    ).encode()
    body = b"".join(struct.pack(endian + fmt * 3, *p) for p in POINTS)
    for face in [*TRIANGLES, QUAD]:
        body += struct.pack(endian + "B" + "I" * len(face), len(face), *face)
    return head + body + struct.pack(endian + "h", 7)


def obj_text() -> bytes:
    lines = ["# fuzz seed", "o solid"]
    lines += [f"v {x:g} {y:g} {z:g}" for x, y, z in POINTS]
    lines += ["vn 0 0 1", "vt 0.5 0.5"]
    lines += [f"f {a + 1}//1 {b + 1}/1/1 {c + 1}" for a, b, c in TRIANGLES[:-1]]
    lines += ["f -6 -1 -5", "f " + " ".join(str(i + 1) for i in QUAD)]
    return ("\n".join(lines) + "\n").encode()


def stl_ascii() -> bytes:
    lines = ["solid fuzz"]
    for face in TRIANGLES:
        lines += ["  facet normal 0 0 1", "    outer loop"]
        lines += [f"      vertex {x:g} {y:g} {z:g}" for x, y, z in POINTS[face]]
        lines += ["    endloop", "  endfacet"]
    lines.append("endsolid fuzz")
    return ("\n".join(lines) + "\n").encode()


def stl_binary() -> bytes:
    data = b"fuzz seed".ljust(80, b" ") + struct.pack("<I", len(TRIANGLES))
    for face in TRIANGLES:
        data += struct.pack("<3f", 0, 0, 1)
        data += b"".join(struct.pack("<3f", *POINTS[i]) for i in face)
        data += b"\0\0"
    return data


def export_csv() -> bytes:
    row = csvio.MeasurementRow(
        mesh_name="bone_12",
        date="2024-05-01T14:03:11+02:00",
        number=1,
        break_number=2,
        colors="#E69F00/#0072B2",
        user_data="=ridge, proximal",
        angle=97.5,
        n_vertices=812,
        radius=3.0,
        x=1.25,
        y=-2.5,
        z=0.1,
        fit=0.0123,
        lam=2.0,
        patch="euclidean",
        n_plus=400,
        n_minus=412,
        fit_plus=0.01,
        fit_minus=0.0023,
        normal_plus=(0.0, 0.0, 1.0),
        normal_minus=(1.0, 0.0, 0.0),
        requested=(1.2, -2.5, 0.1),
        snap_distance=0.05,
        units="mm",
    )
    return csvio.format_measurements_csv([row, row]).encode()


MESHLAB_CSV = (
    b"Mesh Name,Date,Measurement #,Break #,Colors,User Data,Angle,Number of Vertices,Radius,"
    b"x,y,z,fit,SegParam\n"
    b"bone.ply,Tue Mar  2 14:03:11 2021,1,1,Red/Blue, ,97.12,1234,3.0,1.2,-2.3,0.1,0.01,2.0\n"
    b'bone.ply,Tue Mar  2 14:05:40 2021,2.05,2,Red/Green,"a, b",121.5,98,0.8,10,20,30,fill,1.5\n'
)
POINTS_CSV = b"x,y,z,radius,lambda,patch,label\n0,0,0,0.5,2,geodesic,a\n1,2,3,,,,\n"

MESH_SEEDS = {
    "ascii.ply": ply_ascii(),
    "little.ply": ply_binary("little", "double"),
    "big.ply": ply_binary("big", "float"),
    "mesh.obj": obj_text(),
    "ascii.stl": stl_ascii(),
    "binary.stl": stl_binary(),
}
CSV_SEEDS = {
    "export.csv": export_csv(),
    "meshlab.csv": MESHLAB_CSV,
    "points.csv": POINTS_CSV,
}

# Text that readers meet in damaged or hostile files.
TOKENS = [
    b" ",
    b"\n",
    b"\r\n",
    b"\t",
    b",",
    b'"',
    b";",
    b"#",
    b"/",
    b"//",
    b"-",
    b"+",
    b".",
    b"e",
    b"0",
    b"-1",
    b"1.5",
    b"nan",
    b"inf",
    b"-inf",
    b"1e999",
    b"1e-999",
    b"255",
    b"256",
    b"65536",
    b"2147483648",
    b"4294967295",
    b"-2147483649",
    b"18446744073709551616",
    b"9" * 30,
    b"\x00",
    b"\xff\xfe",
    b"\xef\xbb\xbf",
    b"\xc3\x28",
    b"ply",
    b"end_header",
    b"element vertex 4000000000\n",
    b"element face 99999999999\n",
    b"property double x\n",
    b"property list uchar int vertex_indices\n",
    b"property list int int vertex_indices\n",
    b"format binary_big_endian 1.0\n",
    b"format ascii 1.0\n",
    b"v 1 2 3\n",
    b"f 1 2 3 4 5\n",
    b"f 0 0 0\n",
    b"facet normal",
    b"vertex 1 2 3",
    b"solid",
    b"endsolid",
    b"x,y,z\n",
    b"Break #",
    b"SegParam",
    b"0.25",
    b"3 0 1 2",
]

_fraction = st.floats(min_value=0.0, max_value=1.0)
MUTATION = st.one_of(
    st.tuples(st.just("flip"), _fraction, st.integers(0, 255)),
    st.tuples(st.just("insert"), _fraction, st.sampled_from(TOKENS)),
    st.tuples(st.just("delete"), _fraction, st.integers(1, 64)),
    st.tuples(st.just("truncate"), _fraction),
    st.tuples(st.just("duplicate"), _fraction, st.integers(1, 256)),
    st.tuples(st.just("word"), _fraction, st.sampled_from(TOKENS)),
)
# Mesh files also lose a line, repeat one or get a value appended to one: a count that no longer
# matches the lines must be refused, never read shifted. (A CSV that loses its rows to these is
# a valid empty CSV, hence mesh files only.)
MESH_MUTATION = st.one_of(
    MUTATION,
    st.tuples(st.just("append"), _fraction, st.sampled_from(TOKENS)),
    st.tuples(st.just("line"), _fraction, st.sampled_from(["drop", "repeat"])),
)


def mutate(data: bytes, mutations) -> bytes:
    buffer = bytearray(data)
    for mutation in mutations:
        at = int(mutation[1] * len(buffer))
        if mutation[0] == "flip" and buffer:
            buffer[min(at, len(buffer) - 1)] = mutation[2]
        elif mutation[0] == "insert":
            buffer[at:at] = mutation[2]
        elif mutation[0] == "delete":
            del buffer[at : at + mutation[2]]
        elif mutation[0] == "truncate":
            del buffer[at:]
        elif mutation[0] == "duplicate":
            buffer[at:at] = buffer[at : at + mutation[2]]
        elif mutation[0] == "word":
            words = bytes(buffer).split(b" ")
            words[min(int(mutation[1] * len(words)), len(words) - 1)] = mutation[2]
            buffer = bytearray(b" ".join(words))
        elif mutation[0] in ("append", "line"):
            lines = bytes(buffer).split(b"\n")
            k = min(int(mutation[1] * len(lines)), len(lines) - 1)
            if mutation[0] == "append":
                lines[k] += b" " + mutation[2]
            elif mutation[2] == "drop":
                del lines[k]
            else:
                lines.insert(k, lines[k])
            buffer = bytearray(b"\n".join(lines))
    return bytes(buffer)


class _TimeoutError(Exception):
    pass


def _alarm(signum, frame):
    raise _TimeoutError


def _address_space() -> int:
    with open("/proc/self/statm") as handle:
        return int(handle.read().split()[0]) * resource.getpagesize()


@contextlib.contextmanager
def bounded(seconds: int, extra: int):
    """Fail a call that runs longer than ``seconds`` or maps more than ``extra`` new bytes."""
    soft, hard = resource.getrlimit(resource.RLIMIT_AS)
    cap = _address_space() + extra
    if hard != resource.RLIM_INFINITY:
        cap = min(cap, hard)
    previous = signal.signal(signal.SIGALRM, _alarm)
    resource.setrlimit(resource.RLIMIT_AS, (cap, hard))
    signal.alarm(seconds)
    try:
        yield
    finally:
        signal.alarm(0)
        resource.setrlimit(resource.RLIMIT_AS, (soft, hard))
        signal.signal(signal.SIGALRM, previous)


def check_call(read, path: Path, peak_bytes: int = PEAK_BYTES):
    """Run ``read(path)`` bounded; return its result or the GoniometerError it raised."""
    too_much = f"{read.__name__} tried to allocate more than {peak_bytes >> 20} MiB"
    started = not tracemalloc.is_tracing()
    if started:
        tracemalloc.start()
    tracemalloc.reset_peak()
    try:
        with bounded(SECONDS_PER_CALL, EXTRA_ADDRESS_SPACE):
            result = read(path)
    except GoniometerError as error:
        message = str(error)
        assert path.name in message, f"the message does not name the file: {message}"
        assert "Traceback" not in message and len(message) < 5000
        result = error
    except _TimeoutError:
        pytest.fail(f"{read.__name__} did not finish within {SECONDS_PER_CALL} s")
    except MemoryError:
        pytest.fail(too_much)
    finally:
        peak = tracemalloc.get_traced_memory()[1]
        if started:
            tracemalloc.stop()
    if peak > peak_bytes:
        pytest.fail(too_much)
    return result


def assert_sound_mesh(mesh: meshio.MeshData):
    assert mesh.points.ndim == 2 and mesh.points.shape[1] == 3 and mesh.n_vertices > 0
    assert np.isfinite(mesh.points).all()
    if mesh.triangles is not None:
        assert mesh.triangles.ndim == 2 and mesh.triangles.shape[1] == 3
        assert mesh.triangles.min() >= 0 and mesh.triangles.max() < mesh.n_vertices
    if mesh.normals is not None:
        assert mesh.normals.shape == mesh.points.shape and np.isfinite(mesh.normals).all()


def assert_sound_rows(rows, data: bytes):
    # No rows only from a file of a header alone (an export of no measurements reads back so).
    assert rows or not [line for line in data.split(b"\n")[1:] if line.strip(b' \t\r,"')]
    for row in rows:
        values = [row.x, row.y, row.z] if hasattr(row, "row_number") else []
        assert all(math.isfinite(v) for v in values)
        if hasattr(row, "row_number"):
            assert row.radius is None or row.radius > 0
            assert row.lam is None or row.lam >= 0
            assert row.break_number is None or 1 <= row.break_number <= csvio.MAX_BREAK_NUMBER


FUZZ = settings(
    max_examples=60,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow],
)


@pytest.mark.parametrize("seed", MESH_SEEDS)
def test_the_mesh_seeds_are_valid(seed):
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / seed
        path.write_bytes(MESH_SEEDS[seed])
        mesh = meshio.read_mesh(path)
    assert mesh.n_vertices == len(POINTS) and mesh.n_triangles in (5, 7)
    assert_reads_like_the_oracle(seed, MESH_SEEDS[seed], mesh)
    # STL merges corners into vertices in order of first use: compare the sets of points
    np.testing.assert_allclose(np.unique(mesh.points, axis=0), np.unique(POINTS, axis=0), atol=1e-6)


@pytest.mark.parametrize("seed", MESH_SEEDS)
@FUZZ
@given(mutations=st.lists(MESH_MUTATION, min_size=1, max_size=4))
def test_mesh_readers_on_mutated_files(seed, mutations):
    data = mutate(MESH_SEEDS[seed], mutations)
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / seed
        path.write_bytes(data)
        result = check_call(meshio.read_mesh, path)
    if isinstance(result, meshio.MeshData):
        assert_sound_mesh(result)
        assert_reads_like_the_oracle(seed, data, result)


@pytest.mark.parametrize("seed", CSV_SEEDS)
@FUZZ
@given(mutations=st.lists(MUTATION, min_size=1, max_size=4))
def test_csv_readers_on_mutated_files(seed, mutations):
    data = mutate(CSV_SEEDS[seed], mutations)
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / seed
        path.write_bytes(data)
        for read in (csvio.read_replication_csv, csvio.read_measurements_csv):
            result = check_call(read, path)
            if isinstance(result, list):
                assert_sound_rows(result, data)


def test_the_csv_seeds_are_valid():
    with tempfile.TemporaryDirectory() as folder:
        for name, data in CSV_SEEDS.items():
            path = Path(folder) / name
            path.write_bytes(data)
            assert len(csvio.read_replication_csv(path)) == 2
        assert len(csvio.read_measurements_csv(Path(folder) / "export.csv")) == 2


def test_a_forged_vertex_count_is_refused_without_allocating_it(tmp_path):
    path = tmp_path / "forged.ply"
    path.write_bytes(
        MESH_SEEDS["little.ply"].replace(b"element vertex 6", b"element vertex 4000000000")
    )
    result = check_call(meshio.read_mesh, path)
    assert isinstance(result, GoniometerError)


def test_the_bounds_catch_a_hang_and_a_runaway_allocation(tmp_path):
    path = tmp_path / "x.ply"
    path.write_bytes(b"ply\n")

    def hang(_path):
        while True:
            pass

    def hog(_path):
        # Far past the cap: freed memory a long test session keeps mapped cannot absorb it
        # (np.empty: were the cap ever missing, nothing would be touched).
        return np.empty(PEAK_BYTES // 8 + (1 << 31))

    for function, why in ((hang, "did not finish"), (hog, "tried to allocate")):
        with pytest.raises(pytest.fail.Exception, match=why):
            check_call(function, path)
    assert os.path.exists(path)


def test_a_word_in_ascii_ply_data_is_named_with_its_line(tmp_path):
    path = tmp_path / "word.ply"
    path.write_bytes(MESH_SEEDS["ascii.ply"].replace(b"\n1 0 0 ", b"\n1 0 zero "))
    with pytest.raises(GoniometerError, match=r"'.*word\.ply', line 15 \('zero'\): .*not a number"):
        meshio.read_mesh(path)


def test_an_index_out_of_range_names_its_line(tmp_path):
    path = tmp_path / "index.ply"
    path.write_bytes(MESH_SEEDS["ascii.ply"].replace(b"\n3 2 3 4\n", b"\n3 2 3 40\n"))
    with pytest.raises(GoniometerError, match=r"'.*index\.ply', line 22: .*vertex 40 "):
        meshio.read_mesh(path)
