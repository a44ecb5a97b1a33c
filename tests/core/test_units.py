"""The unit of a scan's coordinates: the guess, the scene's symbol, the CSV's Units cell."""

import pytest

from vg_addon import units


@pytest.mark.parametrize(
    ("extent", "unit"),
    [(30.0, "MM"), (2.0, "MM"), (1500.0, "MM"), (1.999, "M"), (0.03, "M"), (float("nan"), "M")],
)
def test_the_guess_reads_a_scan_a_few_units_across_as_millimetres(extent, unit):
    assert units.guess_unit(extent) == unit


def test_the_scene_symbol_names_a_unit_only_where_one_blender_unit_is_exactly_it():
    assert units.scene_symbol("METRIC", 1.0) == "m"
    assert units.scene_symbol("METRIC", 0.001) == "mm"
    assert units.scene_symbol("IMPERIAL", 0.0254) == "in"
    assert units.scene_symbol("METRIC", 0.5) == "BU"
    assert units.scene_symbol("NONE", 0.001) == "BU"


def test_a_units_cell_names_a_unit_only_when_it_is_one():
    assert units.unit_of_text("mm") == "MM"
    assert units.unit_of_text("µm (the scan's coordinates)") == "UM"
    assert units.unit_of_text("um") == "UM"
    for text in ("", "BU", "BU (1 BU = 1 m, shown in meters)", "mesh units (1 unit = 0.01 m)"):
        assert units.unit_of_text(text) is None
    for key, symbol in units.SYMBOLS.items():  # what the CSV writes reads back
        assert units.unit_of_text(symbol) == key
    # What a batch run with --units writes: the scene's length of one BU, in metres (%g).
    for text, key in (("BU (1 BU = 0.001 m, shown in millimeters)", "MM"),
                      ("BU (1 BU = 1e-06 m, shown in micrometers)", "UM"),
                      ("BU (1 BU = 0.0254 m, shown in inches)", "IN"),
                      ("BU (1 BU = 0.3048 m, shown in feet)", "FT"),
                      ("BU (1 BU = 0.5 m, shown in meters)", None),
                      ("mesh units (1 unit = 0.001 m in the scene, object scale 2)", None)):  # fmt: skip
        assert units.unit_of_text(text) == key, text


def test_a_length_shows_five_digits_and_its_unit():
    assert units.length_text(0.3, "mm") == "0.3 mm"
    assert units.length_text(12.345678, "µm") == "12.346 µm"
