"""Objects added to or deleted from an archive are named by their path, at every level
(the root, /shared, a shared group, a shot); an archive sealed before the member lists were
recorded (root table version 1) still verifies, and its next append records them."""
import shutil
from pathlib import Path

import h5py
import pytest
from test_archive_flips import tiny_entry

from instruments.archive import Archive

OLD = Path(__file__).parent / "data" / "root_digest_v1.h5"  # written by the code before this change


@pytest.fixture
def archive(tmp_path):
    a = Archive(tmp_path / "a.h5")
    a.append([tiny_entry(1), tiny_entry(2), tiny_entry(3, truth=False)])
    return a


def _edit(a: Archive, change) -> dict:
    with h5py.File(a.path, "a") as f:
        change(f)
    return a.verify()


CHANGES = {
    "a dataset added at the root": (lambda f: f.create_dataset("foo", data=1.0), None, "added: /foo"),
    "a group added at the root": (lambda f: f.create_group("shot_000009"), None, "added: /shot_000009"),
    "a shot deleted": (lambda f: f.__delitem__("shot_000002"), 2, "missing: /shot_000002"),
    "a channel deleted": (lambda f: f.__delitem__("shot_000003/data/CH2"), 3, "missing: /shot_000003/data/CH2"),
    "a group deleted in a shot": (lambda f: f.__delitem__("shot_000001/truth"), 1, "missing: /shot_000001/truth"),
    "a group added in a shot": (lambda f: f.create_group("shot_000003/notes").create_dataset("x", data=1), 3,
                                "added: /shot_000003/notes"),
    "a dataset added in a shot": (lambda f: f.create_dataset("shot_000001/data/extra", data=1), 1,
                                  "added: /shot_000001/data/extra"),
    "a dataset added to shared": (lambda f: f.create_dataset("shared/x", data=1), None, "added: /shared/x"),
}


@pytest.mark.parametrize("what", CHANGES)
def test_an_added_or_deleted_object_is_named_by_its_path(archive, what):
    change, shot, reason = CHANGES[what]
    report = _edit(archive, change)
    rows = [b for b in report["bad"] if b["reason"].startswith(reason)]
    assert len(rows) == 1, report["bad"]
    path = reason.split(": ", 1)[1]
    assert rows[0]["where"] == path and rows[0]["shot"] == shot
    # the row is the finding, not buried under its consequences: no member-list row, no
    # row for the attributes or members of what was deleted
    assert not [b for b in report["bad"] if b["where"].startswith(path + "@") or b["where"].startswith(path + "/")]
    assert not [b for b in report["bad"] if b["reason"].split(" (")[0].endswith("/: damaged")]
    assert report["shots"] == 3 and report["ok"] == (3 if shot is None else 2)


def test_a_shared_group_edited_names_the_shots_that_use_it(archive):
    key = next(k for k in h5py.File(archive.path, "r")["shared"] if k.startswith("scene_"))
    report = _edit(archive, lambda f: f["shared"][key].__delitem__("settings"))
    rows = [b for b in report["bad"] if b["reason"].startswith("missing: ")]
    assert [(b["where"], b["shots"]) for b in rows] == [(f"/shared/{key}/settings", [1, 2])], report["bad"]


def test_a_deleted_shared_group_names_the_shots_that_linked_to_it(archive):
    # layout 4: only a scene's shots share a group (a real shot alone holds its texts itself)
    report = _edit(archive, lambda f: f.__delitem__("shared/scene_tiny"))
    rows = [b for b in report["bad"] if b["reason"].startswith("missing: ")]
    assert [(b["where"], b["shots"], b["reason"]) for b in rows] == \
        [("/shared/scene_tiny", [1, 2], "missing: /shared/scene_tiny (shared by shots 1, 2)")], report["bad"]
    assert report["ok"] == 1


def test_an_untouched_archive_verifies_clean(archive):
    assert archive.verify() == {"shots": 3, "ok": 3, "bad": []}


def test_an_archive_sealed_before_member_lists_still_verifies_and_gets_them_on_append(tmp_path):
    a = Archive(tmp_path / "old.h5")
    shutil.copyfile(OLD, a.path)
    with h5py.File(a.path, "r") as f:
        assert "members" not in f.attrs  # the fixture is of the first root table
    assert a.verify() == {"shots": 2, "ok": 2, "bad": []}
    assert a.read(1).record.waveforms.keys() == {"CH1", "CH2"}
    a.append([tiny_entry(4)])
    assert a.verify() == {"shots": 3, "ok": 3, "bad": []}
    report = _edit(a, lambda f: f.create_dataset("foo", data=1.0))
    assert [b["reason"] for b in report["bad"]] == ["added: /foo"]


def test_upgrade_records_the_member_lists_of_an_old_sealed_archive_that_verifies(tmp_path, capsys):
    from rig.cli import main

    a = Archive(tmp_path / "old.h5")
    shutil.copyfile(OLD, a.path)
    before = a.digests()
    assert main(["upgrade", str(a.path), "--json"]) == 0
    assert '"members_recorded": true' in capsys.readouterr().out
    assert a.digests() == before and a.verify() == {"shots": 2, "ok": 2, "bad": []}
    report = _edit(a, lambda f: f.__delitem__("shot_000002"))  # now a deleted shot is named
    assert [b["reason"] for b in report["bad"]] == ["missing: /shot_000002"]
    assert main(["upgrade", str(tmp_path / "old.h5")]) == 0  # the second time: nothing to do
    assert capsys.readouterr().out.endswith("already in the current layout\n")


def test_upgrade_refuses_to_record_the_members_of_a_damaged_old_archive(tmp_path, capsys):
    from rig.cli import main

    a = Archive(tmp_path / "old.h5")
    shutil.copyfile(OLD, a.path)
    with h5py.File(a.path, "a") as f:
        del f["shot_000001/title"]
    pristine = a.path.read_bytes()
    assert main(["upgrade", str(a.path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "/shot_000001/title" in err and "verifies" in err, err
    assert a.path.read_bytes() == pristine


MEMBER_LIST_LOST = {
    "the member list deleted": lambda f: f.attrs.__delitem__("members"),
    "the member list rewritten to name what was added": lambda f: f.attrs.__setitem__(
        "members", f.attrs["members"].replace('"/": [', '"/": ["bar", ').replace('"/shared": [', '"/shared": ["x", ')),
    "the member list unreadable": lambda f: f.attrs.__setitem__("members", "{not json"),
}


@pytest.mark.parametrize("what", MEMBER_LIST_LOST)
def test_without_a_trustworthy_member_list_what_no_checksum_covers_is_still_named(archive, what):
    def change(f):
        f.create_group("bar")
        f.create_dataset("shared/x", data=1)
        MEMBER_LIST_LOST[what](f)

    report = _edit(archive, change)
    reasons = [b["reason"] for b in report["bad"]]
    assert "attribute @members: damaged" in reasons, reasons
    assert [(b["where"], b["shot"]) for b in report["bad"] if b["reason"].startswith("added: ")] == \
        [("/bar", None), ("/shared/x", None)], reasons
    assert report["shots"] == 3 and report["ok"] == 3  # the shots themselves are intact
