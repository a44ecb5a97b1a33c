"""Which way round a measurement's sides are painted (vg_addon.method.break_sides): one face of
a break keeps one colour although Algorithm 1's binormal turns over between centres."""

import numpy as np

from vg_addon import Surface
from vg_addon.method.break_sides import paint_swapped
from vg_addon.synthetic_meshes import wedge


def test_no_earlier_measurement_or_a_tie_keeps_the_sides_as_measured():
    assert not paint_swapped([0, 1, 0], [0, -1, 0], [0, 0, 0], 1.0, [])
    assert not paint_swapped(
        [0, 1, 0], [0, -1, 0], [0, 0, 0], 1.0, [([1, 0, 0], [1, 0, 0], [0, 0, 0])]
    )


def test_swapped_when_plus_agrees_with_the_earlier_second_colour():
    earlier = [([0.0, 0.6, 0.8], [0.0, -0.6, 0.8], [0.0, 0.0, 0.0])]
    assert paint_swapped([0.0, -0.6, 0.8], [0.0, 0.6, 0.8], [0.1, 0, 0], 0.3, earlier)
    assert not paint_swapped([0.0, 0.6, 0.8], [0.0, -0.6, 0.8], [0.1, 0, 0], 0.3, earlier)


def test_the_measurements_beside_it_count_more_than_the_far_end_of_a_curved_break():
    # Far away (the faces have turned over along the break), two measurements say one thing;
    # the one beside the new measurement says the other and wins.
    far = ([0.0, -0.6, 0.8], [0.0, 0.6, 0.8], [10.0, 0.0, 0.0])
    near = ([0.0, 0.6, 0.8], [0.0, -0.6, 0.8], [0.2, 0.0, 0.0])
    assert not paint_swapped([0.0, 0.6, 0.8], [0.0, -0.6, 0.8], [0, 0, 0], 0.3, [far, far, near])


def test_along_a_crease_whose_binormal_turns_over_each_face_gets_one_colour():
    c = np.sqrt(0.5)
    rotation = np.array([[c, c, 0.0], [-c, c, 0.0], [0.0, 0.0, 1.0]])  # crease along (1, -1, 0)
    mesh = wedge(90.0, n=40, irregular=True)
    surface = Surface(
        (mesh.points @ rotation.T).astype(np.float32).astype(np.float64), mesh.triangles
    )
    across = rotation @ [0.0, 1.0, 0.0]
    earlier, first_faces, plus_faces = [], set(), set()
    for x in np.linspace(-0.6, 0.6, 13):
        m = surface.measure(rotation @ [x, 0.0, 0.0], 0.3)
        swapped = paint_swapped(m.normal_plus, m.normal_minus, m.center, m.radius, earlier)
        first, second = (
            (m.normal_minus, m.normal_plus) if swapped else (m.normal_plus, m.normal_minus)
        )
        earlier.append((first, second, m.center))
        plus_faces.add(float(np.sign(m.normal_plus @ across)))
        first_faces.add(float(np.sign(first @ across)))
    assert plus_faces == {1.0, -1.0}  # the binormal did turn over
    assert len(first_faces) == 1
