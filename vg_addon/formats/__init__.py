"""File formats: mesh files in (``meshio``: PLY, OBJ, STL) and measurement CSVs in and out
(``csvio``: the extension's own CSV and the replication formats of earlier tools)."""
