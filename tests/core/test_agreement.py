"""The words an import adds about how its re-measured angles agree with the file's."""

import math

from vg_addon.workflow.agreement import agreement


def test_angles_that_come_back_exactly_say_so():
    agreed = agreement(
        [90.0, 60.000000001], [90.0, 60.000000001], ["float32", ""], ["float32"] * 2, [False] * 2
    )
    assert (agreed.compared, agreed.differing, agreed.largest) == (2, 0, 0.0)
    assert agreed.text == "; all 2 angles equal the file's exactly"


def test_one_ulp_off_is_a_difference_and_another_precision_is_named_as_the_reason():
    off = math.nextafter(90.0, 91.0)
    agreed = agreement(
        [90.0, 60.0, 45.0, 30.0, 20.0],
        [off, 60.0008, 45.0, 30.5, 20.1],
        ["float64", "float32", "float32", "float32", ""],
        ["float32", "float64", "float32", "float32", "float32"],
        [False] * 5,
    )
    assert (agreed.compared, agreed.differing, agreed.other_precision) == (5, 4, 2)
    assert agreed.largest == abs(30.5 - 30.0)
    assert agreed.text.startswith("; 4 of 5 angles differ from the file's, by up to 0.5° (")
    assert "2 measured at another precision than the file's" in agreed.text
    assert "2 on a mesh or with a version other than the file's" in agreed.text


def test_a_precision_not_known_on_either_side_is_not_named_as_the_reason():
    """Only two known precisions that differ explain a difference: an empty one on either side
    says nothing (the re-measurement's empty was counted as "another precision")."""
    agreed = agreement(
        [90.0, 80.0, 70.0], [90.5, 80.5, 70.5], ["float32", "", "float32"],
        ["", "float32", "float64"], [False] * 3,
    )  # fmt: skip
    assert (agreed.differing, agreed.other_precision) == (3, 1)
    assert "1 measured at another precision than the file's" in agreed.text
    assert "2 on a mesh or with a version other than the file's" in agreed.text


def test_rows_without_an_angle_are_not_compared_and_stale_rows_are_counted_apart():
    agreed = agreement([None, 50.0, 70.0, 80.0], [10.0, 51.0, 70.0, None], ["", "float32",
                       "float32", "float32"], ["float32"] * 4, [False, True, False, False])  # fmt: skip
    assert (agreed.compared, agreed.differing, agreed.stale) == (1, 0, 1)
    assert agreed.text == (
        "; all 1 angles equal the file's exactly; 1 row(s) marked Stale (measured before the "
        "mesh was edited) not compared"
    )


def test_nothing_to_compare_adds_nothing():
    assert agreement([None], [10.0], [""], [""], [False]).text == ""
    assert agreement([], [], [], [], []).text == ""


def test_a_reading_that_is_not_a_number_is_not_compared():
    agreed = agreement([90.0, 80.0], [float("nan"), 80.0], ["float32"] * 2, ["float32"] * 2,
                       [False, False])  # fmt: skip
    assert (agreed.compared, agreed.differing) == (1, 0)
    assert agreement([None], [10.0], [""], [""], [True]).stale == 1  # stale, angle or not


def test_rows_whose_rule_was_dropped_are_said_to_be_measured_with_the_papers_rule():
    """Only rows of a file of a version that records the rule: an older file's rows were
    measured with the paper's rule, so that is not why they differ."""
    agreed = agreement(
        [90.0, 80.0, 70.0, 60.0],
        [90.5, 80.5, 70.5, 60.0],
        ["float64", "float64", "float32", "float64"],
        ["float64"] * 4,
        [False] * 4,
        [True, False, True, True],  # the third differs by its precision, the fourth not at all
    )
    assert (agreed.differing, agreed.other_precision, agreed.no_rule) == (3, 1, 1)
    assert "1 without a Rule in a file of a version that records it" in agreed.text
    assert "1 on a mesh or with a version other than the file's" in agreed.text


def test_edges_are_matched_to_the_rows_they_came_from_and_each_change_is_named():
    from vg_addon.formats.csvio import EdgeRow
    from vg_addon.workflow.agreement import LISTED_EDGES, edge_agreement

    def edge(row, mean, points="0 0 0; 1 0 0", **fields):
        return EdgeRow(mesh_name="bone", row_number=row, points=points, mean=mean, n_stations=5,
                       min=mean - 1, max=mean + 1, pooled_angle=mean, **fields)  # fmt: skip

    file_rows = [
        edge(2, 90.0),
        edge(3, 80.0),  # the same points as row 2, measured with other settings
        edge(4, 70.0, error="not measured"),
        edge(5, 60.0, stale=True),
        EdgeRow(mesh_name="bone", row_number=6, points="0 5 0; 1 5 0"),  # its error cleared
        edge(7, 50.0),
        edge(8, 45.0),
    ]
    # A replay numbers its edges afresh, in its own order, and its points may be in other
    # coordinates: each carries the row it was measured from.
    replayed = [
        edge(3, 80.25, points="9 9 9; 8 8 8"),
        edge(2, 90.0),
        edge(5, 61.0),
        edge(6, 40.0),
        EdgeRow(mesh_name="bone", row_number=7, error="the patch holds 3 vertices"),
        # A replay stopped (Ctrl-C) before row 8's edge: not a failure to measure it again.
        EdgeRow(
            mesh_name="bone",
            row_number=8,
            error="edge not measured: the run was stopped before this edge",
        ),
        edge(None, 10.0),  # given on the command line: from no row
    ]
    agreed = edge_agreement(file_rows, replayed)
    counts = (agreed.compared, agreed.stale, agreed.blank, agreed.failed, agreed.stopped)
    assert counts == (2, 1, 1, 1, 1)
    assert agreed.differing == [
        "row 3: mean 80.0000° → 80.2500°, min 79.0000° → 79.2500°, max 81.0000° → 81.2500°, "
        "pooled angle 80.0000° → 80.2500°"
    ]
    assert agreed.text.startswith("; 1 of 2 edges differ from the file's figures (row 3: ")
    assert "; 1 edge(s) could not be measured again" in agreed.text
    assert "; 1 edge(s) not measured again: the run was stopped first" in agreed.text
    assert "; 1 row(s) without figures in the file" in agreed.text
    # One edge the same: said in the singular; a change below four decimals shown in full.
    assert edge_agreement(file_rows[:1], replayed[1:2]).text == (
        "; its edge's stations, mean, min, max and pooled angle equal the file's exactly"
    )
    tiny = edge_agreement(file_rows[:1], [edge(2, 90.0 + 1e-11)])
    assert f"mean 90.0° → {90.0 + 1e-11!r}°" in tiny.differing[0]
    many = [edge(n, 50.0) for n in range(LISTED_EDGES + 2)]
    moved = [edge(n, 51.0) for n in range(LISTED_EDGES + 2)]
    text = edge_agreement(many, moved).text
    assert "; and 2 more)" in text and text.count("row ") == LISTED_EDGES
