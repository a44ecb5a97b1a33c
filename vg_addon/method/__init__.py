"""The measuring method: Algorithm 1 of the Virtual Goniometer paper and what it stands on.

- ``algorithm``: Algorithm 1 itself (projection, two-cluster split, a plane per side, the angle).
- ``withinss``: the optimal 1D two-cluster split of the projection.
- ``surface``: a mesh or point cloud prepared once (index, normals), measured many times.
- ``spatial``: the uniform-grid index that finds a patch (the vertices within the radius).
- ``geodesic``: distances along mesh edges, for geodesic patches.
- ``normals``: area-weighted vertex normals, and PCA normals for point clouds.
- ``result``: ``Measurement``, what one measurement returns.
- ``edge_profile``: a whole break edge: traced along the ridge, measured every ``spacing``.
- ``ranges``: the vectorised index-range expansion the index and the graph share.
"""

from .algorithm import goniometer
from .edge_profile import EdgePath, EdgeProfile, EdgeSummary
from .result import Measurement
from .spatial import GridIndex
from .surface import PATCH_MODES, Surface
from .withinss import withinss_split

__all__ = [
    "PATCH_MODES",
    "EdgePath",
    "EdgeProfile",
    "EdgeSummary",
    "GridIndex",
    "Measurement",
    "Surface",
    "goniometer",
    "withinss_split",
]
