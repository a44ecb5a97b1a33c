"""A mesh much finer on one face than on the other: Algorithm 1's split counts vertices, so it
gains more by halving the fine face than by parting the two faces, and the halves read a
near-flat angle with no flag (a 90° wedge, one face meshed ten times finer, read 171.97°). The
refined rule refuses such a split where the faces the normals tell fit far better. Oracle: the
angle the wedge is built with."""

import itertools
import math

import numpy as np
import pytest

from vg_addon import GoniometerError, Surface


def _zip_rows(first, first_x, second, second_x):
    """Triangles joining two rows of vertices along x whose spacings differ."""
    triangles, i, j = [], 0, 0
    while i < len(first) - 1 or j < len(second) - 1:
        if j == len(second) - 1 or (i < len(first) - 1 and first_x[i + 1] <= second_x[j + 1]):
            triangles.append((first[i], first[i + 1], second[j]))
            i += 1
        else:
            triangles.append((first[i], second[j + 1], second[j]))
            j += 1
    return triangles


def two_density_wedge(angle, fine, coarse):
    """A convex wedge of ``angle`` degrees, its crease on the x axis (a shared row of vertices):
    one face a grid of spacing ``fine``, the other of ``coarse``; every vertex on its face."""
    half = math.radians(angle) / 2
    directions = (
        np.array([0.0, math.sin(half), -math.cos(half)]),
        np.array([0.0, -math.sin(half), -math.cos(half)]),
    )
    crease_x = np.linspace(-1, 1, round(2 / min(fine, coarse)) + 1)
    points = [np.column_stack([crease_x, 0 * crease_x, 0 * crease_x])]
    triangles, start = [], len(crease_x)
    for spacing, direction in zip((fine, coarse), directions, strict=True):
        row_x = np.linspace(-1, 1, round(2 / spacing) + 1)
        rows = []
        for t in np.linspace(0, 1, round(1 / spacing) + 1)[1:]:
            rows.append(start + np.arange(len(row_x)))
            start += len(row_x)
            points.append(row_x[:, None] * [1.0, 0.0, 0.0] + t * direction)
        face = _zip_rows(np.arange(len(crease_x)), crease_x, rows[0], row_x)
        for below, above in itertools.pairwise(rows):
            face += _zip_rows(below, row_x, above, row_x)
        triangles.append(np.array(face))
    points, triangles = np.concatenate(points), np.concatenate(triangles)
    edges = points[triangles[:, 1:]] - points[triangles[:, :1]]
    upside_down = np.cross(edges[:, 0], edges[:, 1])[:, 2] < 0  # outward is up here
    triangles[upside_down] = triangles[upside_down][:, ::-1]
    return points, triangles


@pytest.mark.parametrize(
    ("angle", "fine", "radius"),
    [(90, 0.01, 0.5), (90, 0.01, 0.8), (150, 0.0125, 0.8), (120, 0.01, 0.8), (30, 0.01, 0.8)],
)
def test_a_face_ten_times_finer_is_refused_not_read_near_flat(angle, fine, radius):
    """Read before: 171.97°, 172.14°, 170.02°, 168.03° and 177.48°. The last is a split whose
    "+" side all faces the other plane (giving it over leaves that side empty): the faces are
    then parted by the normals alone."""
    points, triangles = two_density_wedge(angle, fine, 0.1)
    with pytest.raises(GoniometerError, match=r"split does not follow the faces.*finely"):
        Surface(points, triangles).measure([0.0, 0.0, 0.0], radius)


@pytest.mark.parametrize("angle", [30, 90, 150])
@pytest.mark.parametrize("ratio", [2, 4])
def test_a_face_a_few_times_finer_still_reads_its_angle(angle, ratio):
    points, triangles = two_density_wedge(angle, 0.1 / ratio, 0.1)
    reading = Surface(points, triangles).measure([0.0, 0.0, 0.0], 0.5)
    assert abs(reading.angle - angle) < 0.01


def test_the_replication_rules_keep_their_readings():
    """The oriented and paper rules replicate earlier measurements as they were taken."""
    points, triangles = two_density_wedge(90, 0.01, 0.1)
    surface = Surface(points, triangles)
    for rule in ("oriented", "paper"):
        assert surface.measure([0.0, 0.0, 0.0], 0.5, rule=rule).angle > 150.0
