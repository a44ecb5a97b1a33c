"""A point cloud's estimated normals can come out the wrong way round on one face of an acute
crease; the reading would then be the supplement of the angle (158° for 22°), with nothing to
show it. Such a reading is refused, saying why; every other reading stands.

Oracle: folds of two exact half-planes at a known angle, sampled here on a grid whose rows miss
the crease line (as a scanner's samples do) and turned by a seeded rotation; the same points
given their true normals.
"""

import math

import numpy as np
import pytest

from vg_addon import GoniometerError, Surface

REFUSAL = "estimated normals face opposite ways"


def fold(angle_deg: float, seed: int, spacing=0.01, half_width=0.3, offset=0.003):
    """Points of two half-planes meeting at ``angle_deg`` along the x axis (before the turn), and
    their outward normals; the rows lie ``offset`` off the crease line."""
    half = math.radians(angle_deg) / 2
    x, s = np.meshgrid(
        np.arange(-half_width, half_width + spacing / 2, spacing),
        np.arange(-half_width, half_width + spacing / 2, spacing) + offset,
        indexing="ij",
    )
    x, s = x.ravel(), s.ravel()
    side = np.where(s >= 0, 1.0, -1.0)
    points = np.column_stack([x, np.abs(s) * side * math.sin(half), -np.abs(s) * math.cos(half)])
    normals = np.column_stack([0 * x, side * math.cos(half), np.full(x.size, math.sin(half))])
    turn, _ = np.linalg.qr(np.random.default_rng(seed).normal(size=(3, 3)))
    if np.linalg.det(turn) < 0:
        turn[:, 0] *= -1
    return points @ turn.T, normals @ turn.T


@pytest.mark.parametrize(("angle", "seed"), [(20.0, 1), (20.0, 2), (22.0, 0), (22.0, 3)])
def test_a_face_oriented_the_wrong_way_round_is_refused_not_read_as_the_supplement(angle, seed):
    points, normals = fold(angle, seed)
    cloud = Surface(points)
    flipped = np.einsum("ij,ij->i", cloud.normals, normals) < 0
    assert 0.3 < flipped.mean() < 0.7  # one face came out inward: the case this guards
    for radius in (0.1, 0.15, 0.2):
        with pytest.raises(GoniometerError, match=REFUSAL):
            cloud.measure([0.0, 0.0, 0.0], radius)
        # Given normals are the caller's: measured, and right.
        given = Surface(points, normals=normals).measure([0.0, 0.0, 0.0], radius)
        assert abs(given.angle - angle) < 1e-6


@pytest.mark.parametrize("angle", [20.0, 25.0, 30.0, 45.0, 60.0, 90.0, 120.0, 150.0, 170.0])
def test_every_cloud_reading_is_right_or_refused(angle):
    right = 0
    for seed in range(6):
        cloud = Surface(fold(angle, seed)[0])
        for radius in (0.1, 0.2):
            try:
                reading = cloud.measure([0.0, 0.0, 0.0], radius).angle
            except GoniometerError as error:
                assert REFUSAL in str(error)
                continue
            assert abs(reading - angle) < 1.5, (seed, radius, reading)
            right += 1
    assert right >= (4 if angle <= 22 else 12)  # at 20° and 22° some turns flip a face
