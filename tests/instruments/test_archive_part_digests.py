"""The master holds each part's digest: a part file replaced by another archive's part of
the same name, whose shots agree with their own tables, is named by verify with the shots
it holds (it had verified "ok", shot 2's seed become 5); a master copied without its
folder, under another name beside the original, is refused an append rather than left
depending on the original's folder."""
import shutil

import pytest
from test_archive_flips import tiny_entry

from instruments.archive import Archive
from instruments.errors import InstrumentError
from rig.cli import main


def _two_parts(path, seeds):
    a = Archive(path)
    for seed in seeds:
        a.append([tiny_entry(seed)])
    return a


def test_a_part_swapped_for_another_archives_part_of_that_name_is_named(tmp_path, capsys):
    ours = _two_parts(tmp_path / "ours.h5", (1, 2))
    theirs = _two_parts(tmp_path / "theirs.h5", (1, 5))
    assert ours.verify()["bad"] == [] and theirs.verify()["bad"] == []
    shutil.copyfile(tmp_path / "theirs.h5.d" / "shots_000002.h5", tmp_path / "ours.h5.d" / "shots_000002.h5")
    report = Archive(ours.path).verify()
    (row,) = report["bad"]
    assert (row["where"], row["shots"]) == ("shots_000002.h5", [2]), row
    assert "is not the one this archive wrote" in row["reason"]
    assert (report["shots"], report["ok"]) == (2, 1)
    assert main(["verify", str(ours.path)]) == 1
    assert "shots_000002.h5" in capsys.readouterr().out


def test_a_master_copied_without_its_folder_is_refused_an_append(tmp_path):
    original = _two_parts(tmp_path / "shots.h5", (1, 2))
    copy = tmp_path / "copy.h5"
    shutil.copyfile(original.path, copy)  # its links still name shots.h5.d, the original's folder
    with pytest.raises(InstrumentError, match=r"copy.h5: cannot append: its shots are links into shots.h5.d"):
        Archive(copy).append([tiny_entry(4)])
    assert not (tmp_path / "copy.h5.d").exists()
    assert Archive(original.path).append([tiny_entry(4)]) == [3]  # the archive that folder belongs to grows


def test_a_swapped_part_names_only_the_shots_this_archive_keeps_in_it(tmp_path):
    """The other archive's part holds shots 5 and 6 under the name of our part of shot 2:
    the row names our shot 2, the one our master links into it; shot 3, in our own intact
    part, stays ok."""
    ours = _two_parts(tmp_path / "ours.h5", (1, 2, 3))
    theirs = Archive(tmp_path / "theirs.h5")
    theirs.append([tiny_entry(1)])
    theirs.append([tiny_entry(5), tiny_entry(6)])  # shots 2 and 3 of theirs, in its shots_000002.h5
    shutil.copyfile(tmp_path / "theirs.h5.d" / "shots_000002.h5", tmp_path / "ours.h5.d" / "shots_000002.h5")
    report = Archive(ours.path).verify()
    assert [(b["where"], b["shots"]) for b in report["bad"]] == [("shots_000002.h5", [2])], report["bad"]
    assert (report["shots"], report["ok"]) == (3, 2)
