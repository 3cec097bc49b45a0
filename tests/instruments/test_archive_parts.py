"""Layouts 3 and 4: a master of external links and one part file per transaction. An append writes
its own part and a new master and copies nothing already stored; a part no master names (a
writer killed between its two renames) is replaced; a missing part is named by verify with
its shots; archives of layouts 2 and 3 are converted by ``rig upgrade`` with every value kept."""
import shutil
from pathlib import Path

import h5py
import numpy as np
import pytest
from test_archive_flips import tiny_entry

from instruments.archive import Archive

OLD = Path(__file__).parent / "data" / "root_digest_v1.h5"  # layout 2, written by the code before layout 3
# layout 3, written by the code before layout 4: OLD upgraded, then shots 3 (scene "tiny") and 4 (real)
LAYOUT3 = Path(__file__).parent / "data" / "layout3.h5"


def _parts(path: Path) -> dict:
    return {p.name: p.read_bytes() for p in sorted(path.parent.glob(path.name + ".d/*.h5"))}


def test_an_append_writes_its_own_part_and_leaves_the_others_untouched(tmp_path):
    path = tmp_path / "a.h5"
    a = Archive(path)
    assert a.append([tiny_entry(1), tiny_entry(2)]) == [1, 2]
    before = _parts(path)
    assert a.append([tiny_entry(3)]) == [3] and a.append([tiny_entry(4, truth=False), tiny_entry(5)]) == [4, 5]
    after = _parts(path)
    assert list(after) == ["shots_000001.h5", "shots_000003.h5", "shots_000004.h5"]
    assert after["shots_000001.h5"] == before["shots_000001.h5"]  # written once, never changed
    with h5py.File(path, "r") as f:
        assert f.attrs["layout_version"] == 4
        link = f.get("shot_000005", getlink=True)
        assert isinstance(link, h5py.ExternalLink) and link.filename == "a.h5.d/shots_000004.h5"
        # shot 5's scene was stored by the first part: its truth is that part's, not a copy
        assert f["shot_000005/truth/forces"].file.filename.endswith("shots_000001.h5")
        assert sorted(f["shared"]) == ["scene_tiny"]  # a real shot alone holds its texts itself
    assert path.stat().st_size < 20_000  # the master holds links, not shots
    assert a.verify() == {"shots": 5, "ok": 5, "bad": []}
    assert a.read(5).seed == 5 and a.read(5).truth["wall_force"][0] == 1.0


def test_a_part_that_no_master_names_is_replaced_by_the_next_append(tmp_path):
    path = tmp_path / "a.h5"
    a = Archive(path)
    a.append([tiny_entry(1)])
    orphan = path.parent / "a.h5.d" / "shots_000002.h5"
    orphan.write_bytes(b"a part renamed into place by a writer killed before its master")
    assert a.ids() == [1] and a.verify()["bad"] == []  # no master names it: readers never see it
    assert a.append([tiny_entry(2)]) == [2]
    assert a.verify() == {"shots": 2, "ok": 2, "bad": []} and a.read(2).seed == 2


def test_a_missing_part_is_named_with_its_shots_and_a_copy_with_its_folder_verifies(tmp_path):
    path = tmp_path / "a.h5"
    a = Archive(path)
    a.append([tiny_entry(1)])
    a.append([tiny_entry(2), tiny_entry(3)])
    copy = tmp_path / "elsewhere" / "a.h5"
    copy.parent.mkdir()
    shutil.copy(path, copy)
    shutil.copytree(path.parent / "a.h5.d", copy.parent / "a.h5.d")
    assert Archive(copy).verify() == {"shots": 3, "ok": 3, "bad": []}
    (path.parent / "a.h5.d" / "shots_000002.h5").unlink()
    report = a.verify()
    assert report["shots"] == 3 and report["ok"] == 1
    assert sorted({b["shot"] for b in report["bad"]}) == [2, 3], report["bad"]
    assert all("\n" not in b["reason"] for b in report["bad"])


def test_upgrade_converts_layout_2_keeping_every_shot_and_its_sharing(tmp_path):
    a = Archive(tmp_path / "old.h5")
    shutil.copyfile(OLD, a.path)
    with h5py.File(a.path, "r") as f:
        assert f.attrs["layout_version"] == 2
        shared = sorted(f["shared"])
    before, entries = a.digests(), [a.read(i) for i in a.ids()]
    assert a.upgrade() == len(entries) and a.upgrade() == 0
    with h5py.File(a.path, "r") as f:
        # each scene's group kept, shared as before; a shot alone (of_shot_N) holds its texts itself
        assert f.attrs["layout_version"] == 4 and sorted(f["shared"]) == [k for k in shared if k.startswith("scene_")]
    assert a.digests() == before and a.verify()["bad"] == []
    for e in entries:
        back = a.read(e.shot_id)
        assert (back.seed, back.settings, back.scene_text, back.start_time) == \
            (e.seed, e.settings, e.scene_text, e.start_time)
    assert a.append([tiny_entry(7)]) == [max(before) + 1]


def _layout3(tmp_path) -> Archive:
    """A copy of the layout-3 archive (its master and its folder of parts)."""
    a = Archive(tmp_path / LAYOUT3.name)  # its links name its folder: the copy keeps the name
    shutil.copyfile(LAYOUT3, a.path)
    shutil.copytree(LAYOUT3.with_name(LAYOUT3.name + ".d"), a.path.with_name(a.path.name + ".d"))
    return a


@pytest.mark.parametrize("layout", [2, 3, 4])
def test_readers_read_layouts_2_3_and_4(tmp_path, layout):
    a = _layout3(tmp_path) if layout == 3 else Archive(tmp_path / "a.h5")
    if layout != 3:
        shutil.copyfile(OLD, a.path)
    if layout == 4:
        a.upgrade()
    with h5py.File(a.path, "r") as f:
        assert f.attrs["layout_version"] == layout
    assert [a.read(i).shot_id for i in a.ids()] == a.ids() and len(a.summary()) == len(a.ids())
    assert a.verify()["bad"] == []


def test_layout_3_grows_in_layout_3_until_upgraded_to_4(tmp_path):
    a = _layout3(tmp_path)
    before, entries = a.digests(), [a.read(i) for i in a.ids()]
    assert a.append([tiny_entry(9)]) == [5]  # a layout-3 archive is still appended to, in layout 3
    with h5py.File(a.path, "r") as f:
        assert f.attrs["layout_version"] == 3 and "instrument" in f["shot_000005"]
        shared = sorted(f["shared"])
    assert a.verify() == {"shots": 5, "ok": 5, "bad": []}
    assert a.upgrade() == 5 and a.upgrade() == 0
    with h5py.File(a.path, "r") as f:  # each scene's group kept; a shot alone holds its texts itself
        assert f.attrs["layout_version"] == 4 and sorted(f["shared"]) == ["scene_tiny"] and "scene_tiny" in shared
        assert "instrument" not in f["shot_000005"] and "scale_factor" in f["shot_000005/data/CH1"].attrs
    # the old parts are gone once the new master names its own
    assert [p.name for p in a.path.with_name(a.path.name + ".d").glob("*.h5")] == ["upgraded_000001.h5"]
    assert a.verify() == {"shots": 5, "ok": 5, "bad": []} and {**before, 5: a.digests()[5]} == a.digests()
    for e in entries:
        back = a.read(e.shot_id)
        assert (back.seed, back.settings, back.scene_text, back.start_time, back.facts) == \
            (e.seed, e.settings, e.scene_text, e.start_time, e.facts)
        for ch, w in e.record.waveforms.items():
            assert np.array_equal(back.record[ch].codes, w.codes) and back.record[ch].preamble == w.preamble
    assert a.append([tiny_entry(10)]) == [6] and a.read(6).seed == 10


def test_the_table_a_writer_seals_is_the_one_the_file_reads(tmp_path):
    """Layout 4's writer makes a shot's table from what it writes, never walking the shot:
    each row must be the one digest.table computes from the file (a hard-linked scene and
    time axis, a scene stored by an earlier part, a shot alone, two time bases, volts)."""
    import json

    from instruments.archive.digest import table
    from instruments.archive.links import OpenParts
    from instruments.archive.stored import stored_table
    from instruments.archive.verify import addresses
    from instruments.records import Preamble, ScopeRecord, Waveform

    two_bases = tiny_entry(7)
    slow = Preamble(points=50, x_increment=2e-6, x_zero=0.0, trigger_index=5, y_multiplier=1.0, y_offset=0.0,
                    y_zero=0.0, y_unit="V")
    waves = {**two_bases.record.waveforms, "CH3": Waveform("CH3", slow, samples=np.linspace(-1, 1, 50))}
    two_bases.record = ScopeRecord(waves, True)
    path = tmp_path / "a.h5"
    a = Archive(path)
    a.append([tiny_entry(1), tiny_entry(2), tiny_entry(3, truth=False), two_bases])
    a.append([tiny_entry(5), tiny_entry(6, truth=False)])  # shot 5: its scene in the first part
    with h5py.File(path, "r") as f, OpenParts() as parts:
        linked = addresses(f["shared/scene_tiny"])
        for n in sorted(k for k in f if k.startswith("shot_")):
            g = parts.group(f, n)
            assert json.loads(stored_table(g)) == table(g, linked), n
    assert a.verify()["bad"] == [] and a.verify()["ok"] == 6
