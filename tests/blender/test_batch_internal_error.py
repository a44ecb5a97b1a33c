"""A bug in a batch run's measuring of one mesh loses none of what was measured before it.

The fault is injected by the test (a step of the pipeline raises an unexpected error on its Nth
call), as a bug would. Before, the mesh's rows were all written as failed, the ones already
measured too. Oracles: the measurements Blender holds on the object afterwards, and the same
run without the fault.
"""

from __future__ import annotations

import importlib

import bpy
import numpy as np
import pytest
from bpy_helpers import mesh_object

from vg_addon.formats import csvio
from vg_addon.synthetic_meshes import wedge

EDGE = {"points": [[-0.6, 0.0, 0.0], [0.6, 0.0, 0.0]], "spacing": 0.15, "radius": 0.3, "lam": 2.0,
        "patch": "euclidean", "mesh_name": "", "note": ""}  # fmt: skip
TASKS = 90
FAULT = "a bug injected by the test"


def _tasks(vg):
    batchplan = importlib.import_module(f"{vg.__name__}.vg_addon.workflow.batchplan")
    return [
        batchplan.Task(
            index=k,
            mesh=0,
            center=(float(x), 0.0, 0.0),
            radius=0.3,
            lam=2.0,
            patch="euclidean",
            number=k + 1,
        )
        for k, x in enumerate(np.linspace(-0.6, 0.6, TASKS))
    ]


def _failing_on_call(function, call: int):
    """``function``, raising a RuntimeError on its ``call``-th call."""
    calls = [0]

    def wrapped(*args, **kwargs):
        calls[0] += 1
        if calls[0] == call:
            raise RuntimeError(FAULT)
        return function(*args, **kwargs)

    return wrapped


def _run(vg, tmp_path, fault=None, **more):
    """Measure the wedge's points and 3 edges through ``safe_measure_mesh``, with ``fault``
    (module, name, call) injected and ``more`` options; returns the result handed over and the
    object."""
    measure = importlib.import_module(f"{vg.__name__}.batch.measure")
    sources = importlib.import_module(f"{vg.__name__}.batch.sources")
    shape = wedge(80.0, n=20, irregular=True, seed=2)
    obj = mesh_object("Wedge", shape.points, shape.triangles)
    options = {"edges": [dict(EDGE) for _ in range(3)], "plots": str(tmp_path / "o"), **more}
    handed = []
    patch = pytest.MonkeyPatch()
    if fault is not None:
        module, name, call = fault
        target = importlib.import_module(f"{vg.__name__}.{module}")
        patch.setattr(target, name, _failing_on_call(getattr(target, name), call))
    try:
        measure.safe_measure_mesh(
            0, sources.MeshSource(obj.name), _tasks(vg), options, None, handed.append
        )
    finally:
        patch.undo()
    assert len(handed) == 1  # the rows are handed over once
    return handed[0], obj


@pytest.mark.parametrize(
    ("fault", "points_kept", "edges_kept"),
    [
        (("bridge.measuring", "record_row", 41), 40, 0),  # recording the 41st point
        (("batch.edges", "_measure_edge", 2), TASKS, 1),  # measuring the second edge
    ],
    ids=["while-recording-points", "while-measuring-edges"],
)
def test_a_bug_keeps_every_row_measured_before_it(
    vg, tmp_path, capfd, fault, points_kept, edges_kept
):
    clean, clean_obj = _run(vg, tmp_path)
    clean_angles = [row.angle for _, row in sorted(clean.rows, key=lambda pair: pair[0])]
    bpy.data.objects.remove(clean_obj)

    result, obj = _run(vg, tmp_path, fault)
    stderr = capfd.readouterr().err
    assert "Traceback" in stderr and FAULT in stderr  # the bug is reported, with its traceback
    rows = [row for _, row in sorted(result.rows, key=lambda pair: pair[0])]
    assert len(rows) == TASKS  # every point has its row
    kept = [row for row in rows if not row.error]
    assert len(kept) == points_kept == result.measured
    # The rows kept are the object's measurements, and read as the run without the bug.
    points = sorted(item.angle for item in obj.vg.measurements if not item.edge_number)
    assert sorted(row.angle for row in kept) == pytest.approx(points, abs=1e-4)
    assert [row.angle for row in kept] == clean_angles[:points_kept]
    for row in rows[points_kept:]:
        assert "internal error" in row.error and FAULT in row.error, row.error
    assert result.failed == TASKS - points_kept

    assert len(result.edge_rows) == 3  # each edge has its summary: measured, or saying why not
    measured_edges = [row for row in result.edge_rows if not row.error]
    assert len(measured_edges) == edges_kept == len(obj.vg.edges)
    for row in result.edge_rows[edges_kept:]:
        assert "internal error" in row.error and FAULT in row.error, row.error
    stations = [row for row in result.station_rows if not row.error]
    assert len(stations) == sum(edge.n_stations for edge in obj.vg.edges)
    bpy.data.objects.remove(obj)


def test_a_bug_after_every_row_is_measured_says_the_pictures_and_colours_are_not_made(
    vg, tmp_path, capfd
):
    """A bug while the object is painted, every row measured: the rows are kept as measured,
    and the run is told that the pictures and colours were not made (it exits 2, an output
    missing), not left to exit 0 with a traceback alone."""
    result, obj = _run(vg, tmp_path, ("bridge.measuring", "repaint", 1))
    assert FAULT in capfd.readouterr().err
    assert result.measured == TASKS and result.failed == 0
    assert all(not row.error for _, row in result.rows)
    assert len(result.picture_errors) == 1
    assert "pictures and colours of Wedge: internal error" in result.picture_errors[0]
    bpy.data.objects.remove(obj)


def test_a_bug_in_a_radius_sweep_gives_each_site_not_swept_its_rows(vg, tmp_path, capfd):
    """``--sweep``: a bug at the fifth site. The four sites swept keep their rows with their
    angles; each later site has a row per radius saying "internal error" (before: no row at
    all, a site the run's count of unswept sites did not see)."""
    sweep = {"sweep": (0.2, 0.4, 3), "sweep_plots": str(tmp_path / "sweep")}
    result, obj = _run(vg, tmp_path, ("batch.measure", "radius_sweep", 5), **sweep)
    assert FAULT in capfd.readouterr().err
    assert result.measured == TASKS  # the points were measured before the sweeps
    angle, error = (csvio.SWEEP_COLUMNS.index(c) for c in ("Angle", "error"))
    by_site = {}
    for index, cells in result.sweep_rows:
        by_site.setdefault(index, []).append(cells)
    assert sorted(by_site) == list(range(TASKS))  # every site has its rows
    assert all(len(rows) == 3 for rows in by_site.values())  # one per radius
    for index, rows in by_site.items():
        if index < 4:
            assert all(cells[angle] and not cells[error] for cells in rows), index
        else:
            assert all(not cells[angle] and FAULT in cells[error] for cells in rows), index
    bpy.data.objects.remove(obj)
