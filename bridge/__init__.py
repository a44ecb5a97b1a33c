"""The bpy bridge: the one place where Blender data meets the NumPy core.

- ``mesh_data``: a Blender object's evaluated mesh as core input, and its cached ``Surface``.
- ``measuring``: the one measuring pipeline every operator, tool and batch run calls.
- ``records``: measurements stored in the .blend (the scene's PropertyGroups) and read back.
- ``colors``: painting the sides of every measurement into a colour attribute.
- ``watch``: marks measurements stale when their mesh changes.
"""
