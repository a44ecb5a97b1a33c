"""The bpy bridge: the one place where Blender data meets the NumPy core.

- ``mesh_data``: a Blender object's evaluated mesh as core input, and its cached ``Surface``.
- ``measuring``: the one measuring pipeline every operator, tool and batch run calls
  (``measure``, then ``record``), and ``repaint``.
- ``replication``: a CSV's rows re-measured on an object (all or nothing), and CSV export.
- ``edges``: edge profiles (stations recorded as one break, the edge record and its plot).
- ``records``: measurements stored in the .blend (the scene's PropertyGroups) and read back.
- ``painting``: incremental painting from kept sides; ``colors``: the "VG Sides" attribute.
- ``watch``: marks measurements stale when their mesh changes, and on file load.
- ``legacy``: world-space records of earlier versions brought into mesh coordinates.
- ``label_data`` and ``measurement_map``: the labels' text and place, and the map's render.
"""
