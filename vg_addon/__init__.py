"""Virtual Goniometer core: break-edge angles on 3D scans, in NumPy alone.

The method is Algorithm 1 of Yezzi-Woodley et al., "The Virtual Goniometer: demonstrating a new
method for measuring angles on archaeological materials using fragmentary bone". Nothing in this
package imports Blender.

>>> from vg_addon import Surface
>>> surface = Surface(points, triangles)          # doctest: +SKIP
>>> surface.measure(center, radius=0.4).angle     # doctest: +SKIP
"""

from .algorithm import goniometer
from .errors import GoniometerError
from .result import Measurement
from .spatial import GridIndex
from .surface import PATCH_MODES, Surface
from .withinss import withinss_split

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
