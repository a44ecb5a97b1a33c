"""The reference meshes a test asks for by name: a file of ``../shared/data`` (the test skips,
saying why, where it is absent) or one of the project's own shapes (in every clone)."""

from __future__ import annotations

from vg_addon.formats.meshio import read_mesh
from vg_addon.reference_shapes import half_annulus, intersecting_spheres

PROJECT_SHAPES = {"project half annulus": half_annulus, "project lens": intersecting_spheres}
REFERENCE_NAMES = ["HalfAnnulus", "IntersectingSpheres", "sample_mesh", *PROJECT_SHAPES]


def reference_mesh(name: str, request):
    """The mesh ``name`` (one of :data:`REFERENCE_NAMES`); ``request`` is the test's, for the
    ``shared_data`` fixture."""
    if name in PROJECT_SHAPES:
        return PROJECT_SHAPES[name]()
    return read_mesh(request.getfixturevalue("shared_data") / f"{name}.ply")
