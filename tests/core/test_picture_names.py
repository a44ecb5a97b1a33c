"""File-name stems of picture files: one per mesh, unique ignoring case, and a stem a mesh's
pictures were written under stays that mesh's (``vg_addon.formats.files``)."""

from vg_addon.formats.files import kept_picture_name, picture_names


def test_two_names_of_one_file_name_get_two_stems():
    stems, notes = picture_names(["bone 1", "bone_1", "BONE_1"])
    assert stems == ["bone_1", "bone_1-2", "BONE_1-3"]
    assert len(notes) == 2


def test_a_stem_taken_elsewhere_is_never_given():
    stems, _ = picture_names(["A_1"], taken=["a_1", "A_1-2"])
    assert stems == ["A_1-3"]


def test_with_no_record_a_safe_name_keeps_its_stem():
    records = {"A 1": "", "A_1": ""}
    assert kept_picture_name("A_1", records) == "A_1"
    assert kept_picture_name("A 1", records) == "A_1-2"


def test_a_recorded_stem_stays_when_an_object_of_the_same_file_name_comes_later():
    """ "A 1" made its map as "A_1" before "A_1" existed: "A_1" must not take that stem
    (its map would write over "A 1"'s pictures)."""
    records = {"A 1": "A_1", "A_1": ""}
    assert kept_picture_name("A 1", records) == "A_1"
    assert kept_picture_name("A_1", records) == "A_1-2"


def test_a_numbered_stem_stays_its_objects():
    records = {"A_1": "", "A 1": "A_1-2", "a 1": "a_1-3"}
    stems = {name: kept_picture_name(name, records) for name in records}
    assert stems == {"A_1": "A_1", "A 1": "A_1-2", "a 1": "a_1-3"}


def test_a_renamed_object_leaves_its_old_stem():
    """The record no longer comes from the name (renamed, or a copy that carried its
    original's record): a stem from the name as it is now."""
    assert kept_picture_name("Femur", {"Femur": "A_1"}) == "Femur"
    records = {"A": "A", "A.001": "A"}
    assert kept_picture_name("A", records) == "A"
    assert kept_picture_name("A.001", records) == "A.001"


def test_two_records_of_one_stem_go_to_the_safe_name_first():
    records = {"A 1": "A_1", "A_1": "A_1"}
    assert kept_picture_name("A_1", records) == "A_1"
    assert kept_picture_name("A 1", records) == "A_1-2"


def test_a_stem_recorded_by_a_renamed_object_is_not_given_to_its_old_name():
    """ "A" mapped, renamed "B", then a new "A": the new one must not write over the
    pictures "B" made as "A"."""
    records = {"B": "A", "A": ""}
    assert kept_picture_name("A", records) == "A-2"
    assert kept_picture_name("B", records) == "B"
