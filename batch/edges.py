"""Measuring ``--edge`` profiles on one mesh of a batch run, through the extension's pipeline."""

from __future__ import annotations

import bpy

from ..bridge import edges, records
from ..properties import exact_numbers
from ..vg_addon import GoniometerError
from ..vg_addon.formats import csvio, profile_plot


def edge_points(spec: dict) -> list:
    """Start, via points and end of one ``--edge`` (see ``cli.EdgeAction``)."""
    return [spec["start"], *spec["via"], spec["end"]]


def failed_edge_row(number: int, spec: dict, mesh_name: str, settings: dict, message: str, units):
    """The output row of an edge that could not be measured."""
    return csvio.MeasurementRow(
        mesh_name=mesh_name,
        date=csvio.now_iso(),
        radius=settings["radius"],
        seg_param=settings["lam"],
        patch=settings["patch"],
        requested=tuple(float(v) for v in spec["start"]),
        edge_number=number,
        spacing=settings["spacing"],
        units=units,
        extension_version=records.extension_version(),
        blender_version=bpy.app.version_string,
        error=f"edge not measured: {message}",
    )


def measure_edges(obj, options: dict, units: str, safe_name: str):
    """Measure every ``--edge`` on ``obj``, record each as one break of stations, and write
    each profile's plot beside the output CSV.

    Returns
    -------
    station_rows : list of csvio.MeasurementRow
        Every edge's stations in order, or one error row for an edge that failed.
    edge_rows : list of csvio.EdgeRow
        One summary per measured edge.
    """
    settings = options["edge_settings"]
    station_rows, edge_rows = [], []
    for spec in options["edges"]:
        number = obj.vg.next_edge_number
        try:
            edge = edges.measure_edge_on_object(
                obj,
                edge_points(spec),
                settings["spacing"],
                settings["radius"],
                settings["lam"],
                settings["patch"],
            )
        except GoniometerError as error:
            obj.vg.next_edge_number = number + 1  # the number stays with the failed edge
            station_rows.append(
                failed_edge_row(number, spec, obj.name, settings, str(error), units)
            )
            continue
        station_rows.extend(
            records.to_row(obj, item, stale=False, units=units)
            for item in obj.vg.measurements
            if item.edge_number == edge.number
        )
        edge_rows.append(records.edge_row(obj, edge, units=units))
        numbers = exact_numbers(edge)
        image = profile_plot.render_profile(numbers["arc_lengths"], numbers["angles"])
        path = f"{options['plots']}_{safe_name}_edge{edge.number}.png"
        profile_plot.write_png(path, image, overwrite=True)
    return station_rows, edge_rows
