"""Virtual Goniometer core: break-edge angles on 3D scans, in NumPy alone.

The method is Algorithm 1 of Yezzi-Woodley et al., "The Virtual Goniometer: demonstrating a new
method for measuring angles on archaeological materials using fragmentary bone". Nothing in this
package imports Blender.

Layout: ``method`` is the measuring method (Algorithm 1, the patch index, the normals);
``formats`` reads and writes mesh files and measurement CSVs; ``workflow`` plans batch runs and
holds the drag tool's state machine; ``palette`` gives the side colours; ``synthetic_meshes``
makes the exact test and demo shapes; ``errors`` is the one error type every refusal raises.

>>> from vg_addon import Surface
>>> surface = Surface(points, triangles)          # doctest: +SKIP
>>> surface.measure(center, radius=0.4).angle     # doctest: +SKIP
"""

from .errors import GoniometerError
from .method import PATCH_MODES, GridIndex, Measurement, Surface, goniometer, withinss_split

__version__ = "0.1.0"

__all__ = [
    "PATCH_MODES",
    "GoniometerError",
    "GridIndex",
    "Measurement",
    "Surface",
    "__version__",
    "goniometer",
    "withinss_split",
]
