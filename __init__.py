"""Virtual Goniometer: measure break-edge angles on 3D scans of bone fragments and stone tools.

The extension root: registers the properties saved in the .blend, the ``vg.*`` operators and the
"Goniometer" sidebar tab. The numerics live in ``vg_addon`` (pure NumPy). Where Blender's Python
has no NumPy (a Linux distribution's Blender), it registers an explanation with the fix instead
(``numpy_missing``).
"""

import bpy

# Checked first, so that a Blender without NumPy gets an explanation, not a bare import error.
try:
    import numpy
except ImportError as error:
    numpy_import_error = error
else:
    numpy_import_error = None

if numpy_import_error is None:
    from . import operators, properties, ui
    from .bridge import edges, measuring, mesh_data, watch

    classes = (*operators.classes, *ui.classes)  # besides properties.classes

    def register():
        properties.register()
        properties.unit_chosen_handlers.append(edges.redraw_plots)
        for cls in classes:
            bpy.utils.register_class(cls)
        operators.drag.register_tool()
        watch.register()
        ui.labels.register()

    def unregister():
        # Blender frees a running modal operator without its cancel(): end its session here.
        operators.view_session.end_all()
        ui.labels.unregister()
        operators.drag.unregister_tool()
        watch.unregister()
        for cls in reversed(classes):
            bpy.utils.unregister_class(cls)
        properties.unregister()
        properties.unit_chosen_handlers.clear()
        mesh_data.clear_cache()
        measuring.clear_cache()

else:
    from . import numpy_missing

    classes = numpy_missing.classes

    def register():
        numpy_missing.register(numpy_import_error)

    def unregister():
        numpy_missing.unregister()
