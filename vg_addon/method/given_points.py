"""Points given in a file or typed, checked to lie on the mesh before an edge is traced."""

from __future__ import annotations

import math

import numpy as np

from ..errors import GoniometerError
from .edge_profile import ridge_graph
from .inputs import as_radius


def check_given_points(surface, points, radius: float, where: str) -> None:
    """Refuse points given in a file or typed (not clicked on the surface) that lie farther than
    ``max(radius, 3 × mean edge length, longest edge length)`` from every vertex: a point picked
    on another copy of the mesh, or in other units, would otherwise snap to some vertex and be
    measured. Any point on a face is within its longest edge of a vertex, so a point clicked on
    the surface (and recorded, exported and read back) always passes, however large its face.

    Parameters
    ----------
    points : array_like, shape (k, 3)
        The edge's start, via points and end, in the surface's coordinates.
    radius : float
        The measuring radius of the edge's stations.
    where : str
        Names the file or edge in the message.

    Raises
    ------
    GoniometerError
        Naming every point too far, its distance and the limit.
    """
    graph = ridge_graph(surface)
    limit = max(as_radius(radius), 3.0 * graph.mean_edge_length, graph.longest_edge_length)
    far = []
    for number, point in enumerate(np.asarray(points, dtype=np.float64), 1):
        _, distance = surface.index.nearest(point, limit)
        if not distance <= limit:
            _, distance = surface.index.nearest(point, math.inf)
            x, y, z = point
            how_far = (
                f"{distance:.6g} from the mesh"
                if math.isfinite(distance)
                else "far from every vertex (beyond what a double holds)"
            )
            far.append(f"point {number} ({x:g}, {y:g}, {z:g}) is {how_far}")
    if far:
        raise GoniometerError(
            f"{where}: {'; '.join(far)}, farther than {limit:.6g} (the radius, three mean edge "
            "lengths or the longest edge): check that the points were picked on this mesh, in "
            "its units and frame."
        )
