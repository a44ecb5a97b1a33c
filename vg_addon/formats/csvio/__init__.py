"""The CSV files of measurements: one module a file kind, this package their one public name.

Callers use ``csvio.X``; the modules behind it each do one job:

- ``text``: the dialect every file is written in and read from (quoting, the spreadsheet
  formula guard, floats as ``repr``, the checks on reading, any other table);
- ``measurements``: the export, :class:`MeasurementRow` (the MeshLab plugin's 14 columns first,
  this extension's after them), written and read back;
- ``edges``: the edge summary file written beside an export, :class:`EdgeRow`;
- ``replication``: the rows to re-measure read from any CSV with x, y and z (the paper's "xyz
  method"), :class:`ReplicationRow`;
- ``mesh_names``: which mesh a row's name refers to;
- ``sweep``: the radius-sweep CSV.

Every writer is atomic (the old file stays intact if anything fails); every reader checks the
whole file and raises one :class:`~vg_addon.errors.GoniometerError` listing every problem, or
returns every row: never part of a file. The format: docs/CSV.md.
"""

from .edges import (
    EDGE_COLUMNS,
    LATER_EDGE_COLUMNS,
    EdgeRow,
    edges_path_for,
    format_edges_csv,
    format_points,
    is_edges_csv,
    parse_edges_csv,
    parse_points,
    read_edges_csv,
    write_edges_csv,
)
from .export_files import SummaryWriteError, holds_edge_summary, write_export
from .measurements import (
    CLOSED_COLUMNS,
    CREASE_COLUMNS,
    EXPORT_COLUMNS,
    LATER_COLUMNS,
    MESHLAB_COLUMNS,
    NOISE_COLUMNS,
    RULE_COLUMNS,
    MeasurementRow,
    format_colors,
    format_measurements_csv,
    now_iso,
    parse_measurements_csv,
    read_measurements_csv,
    replayed_rows,
    writable_row,
    write_measurements_csv,
)
from .mesh_names import (
    check_mesh_names,
    mesh_name_match,
    mesh_name_matches,
    mesh_stem,
    rows_for_mesh,
    rows_for_other_meshes,
)
from .replication import (
    MAX_BREAK_NUMBER,
    SOURCE_FORMATS,
    ReplicationRow,
    break_number_cell,
    parse_replication_csv,
    read_from_export,
    read_replication_csv,
)
from .sweep import SWEEP_COLUMNS, format_sweep_rows, holds_sweep, sweep_cells, write_sweep_csv
from .text import (
    COORDINATE_SPACES,
    MESH_COORDINATES,
    WORLD_COORDINATES,
    format_table,
    header_columns,
    number_cell,
    read_table,
    text_cell,
    write_table,
)

__all__ = [
    "CLOSED_COLUMNS",
    "COORDINATE_SPACES",
    "CREASE_COLUMNS",
    "EDGE_COLUMNS",
    "EXPORT_COLUMNS",
    "LATER_COLUMNS",
    "LATER_EDGE_COLUMNS",
    "MAX_BREAK_NUMBER",
    "MESHLAB_COLUMNS",
    "MESH_COORDINATES",
    "NOISE_COLUMNS",
    "RULE_COLUMNS",
    "SOURCE_FORMATS",
    "SWEEP_COLUMNS",
    "WORLD_COORDINATES",
    "EdgeRow",
    "MeasurementRow",
    "ReplicationRow",
    "SummaryWriteError",
    "break_number_cell",
    "check_mesh_names",
    "edges_path_for",
    "format_colors",
    "format_edges_csv",
    "format_measurements_csv",
    "format_points",
    "format_sweep_rows",
    "format_table",
    "header_columns",
    "holds_edge_summary",
    "holds_sweep",
    "is_edges_csv",
    "mesh_name_match",
    "mesh_name_matches",
    "mesh_stem",
    "now_iso",
    "number_cell",
    "parse_edges_csv",
    "parse_measurements_csv",
    "parse_points",
    "parse_replication_csv",
    "read_edges_csv",
    "read_from_export",
    "read_measurements_csv",
    "read_replication_csv",
    "read_table",
    "replayed_rows",
    "rows_for_mesh",
    "rows_for_other_meshes",
    "sweep_cells",
    "text_cell",
    "writable_row",
    "write_edges_csv",
    "write_export",
    "write_measurements_csv",
    "write_sweep_csv",
    "write_table",
]
