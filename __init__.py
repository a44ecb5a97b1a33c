"""Virtual Goniometer: measure break-edge angles on 3D scans of bone fragments and stone tools.

The extension root: registers the properties saved in the .blend, the ``vg.*`` operators and the
"Goniometer" sidebar tab. The numerics live in ``vg_addon`` (pure NumPy). Where Blender's Python
has no NumPy (a Linux distribution's Blender), it registers an explanation with the fix instead
(``numpy_missing``).
"""

import bpy

try:
    import numpy
except ImportError as error:
    _numpy_error = error
else:
    _numpy_error = None

if _numpy_error is None:
    from . import operators, properties, ui
    from .bridge import measuring, mesh_data, watch

    classes = (*properties.classes, *operators.classes, *ui.classes)

    def register():
        for cls in classes:
            bpy.utils.register_class(cls)
        properties.register_properties()
        operators.drag.register_tool()
        watch.register()

    def unregister():
        operators.drag.unregister_tool()
        watch.unregister()
        properties.unregister_properties()
        for cls in reversed(classes):
            bpy.utils.unregister_class(cls)
        mesh_data.clear_cache()
        measuring.clear_cache()

else:
    from . import numpy_missing

    classes = numpy_missing.classes

    def register():
        numpy_missing.register(_numpy_error)

    def unregister():
        numpy_missing.unregister()
