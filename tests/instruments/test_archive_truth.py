"""A default read returns the shot's truth forces, which the shots of one scene share (one
group under /shared, in the part file that first stored it). An Archive reads and checks them
once per version of that file (instruments/archive/shared.py): a later read of any shot of
the scene takes them from the first, read-only; a file replaced on disk is read and checked
again; the forces of the last FORCES_KEPT groups only are kept. Its first read of a version
reads each of them once (its check takes their rows from the values read); a read that skips
the checksums takes them from the reads before it too.

The tests prove "not read again" by damaging the stored bytes of a truth dataset in place,
keeping the file's identity (inode, size, modification time): a read that went to the file
again would meet the damaged chunk (gzip, fletcher32) and be refused."""
import dataclasses
import os
import shutil
from pathlib import Path

import h5py
import numpy as np
import pytest
from test_archive_flips import tiny_entry

from instruments.archive import Archive, digest, values
from instruments.archive.links import file_identity
from instruments.archive.shared import FORCES_KEPT
from instruments.errors import InstrumentError

OLD = Path(__file__).parent / "data" / "root_digest_v1.h5"  # layout 2: one file, replaced whole per transaction


def _part(path: Path, n: int = 1) -> Path:
    return path.parent / f"{path.name}.d" / f"shots_{n:06d}.h5"


def _flip_in_place(path: Path, dataset: str):
    """Flip a byte in the middle of ``dataset``'s stored (compressed) chunk, writing into the
    file where it is: its identity (inode, size, modification time) kept."""
    with h5py.File(path, "r") as f:
        chunk = f[dataset].id.get_chunk_info(0)
    before, st = file_identity(path), os.stat(path)
    with open(path, "r+b") as fh:
        fh.seek(chunk.byte_offset + chunk.size // 2)
        byte = fh.read(1)[0]
        fh.seek(-1, os.SEEK_CUR)
        fh.write(bytes([byte ^ 0x40]))
    os.utime(path, ns=(st.st_atime_ns, st.st_mtime_ns))
    assert file_identity(path) == before  # the same version, as an Archive tells versions apart


def _scene(seed: int, key: str):
    """tiny_entry of the scene ``key`` (its own shared group, scene_<key>) and its own forces."""
    e = tiny_entry(seed)
    return dataclasses.replace(e, truth_key=key, truth={k: v + seed for k, v in e.truth.items()})


def test_a_later_read_of_a_scene_takes_the_truth_its_first_read_checked(tmp_path):
    path = tmp_path / "a.h5"
    Archive(path).append([tiny_entry(1)])
    Archive(path).append([tiny_entry(2)])  # its truth: an external link to shot 1's part
    a = Archive(path)
    first = a.read(1).truth
    _flip_in_place(_part(path), "shared/scene_tiny/forces/wall_force")
    with pytest.raises(InstrumentError, match="shot 2: shared/scene_tiny/forces/wall_force: damaged"):
        Archive(path).read(2)  # a new reader checks the file and finds the damage
    for shot in (2, 1, 2):  # not read again: the damaged chunk is never met
        truth = a.read(shot).truth
        assert sorted(truth) == sorted(first) == ["upper_average_force", "wall_force"]
        assert all(np.array_equal(truth[k], tiny_entry(1).truth[k]) for k in truth)


def test_the_truth_a_read_returns_is_read_only_and_a_dict_of_its_own(tmp_path):
    path = tmp_path / "a.h5"
    Archive(path).append([tiny_entry(1), tiny_entry(2)])
    a = Archive(path)
    one = a.read(1).truth
    assert not any(v.flags.writeable for v in one.values())
    with pytest.raises(ValueError, match="read-only"):
        one["wall_force"][0] = 5.0
    one["wall_force"] = np.zeros(48)  # the caller's dict: the next read's is another
    del one["upper_average_force"]
    two = a.read(2).truth
    assert sorted(two) == ["upper_average_force", "wall_force"]
    assert np.array_equal(two["wall_force"], tiny_entry(2).truth["wall_force"])
    assert not Archive(path).read(1, verify=False).truth["wall_force"].flags.writeable  # every read's


def test_a_part_replaced_on_disk_is_read_and_checked_again(tmp_path):
    path, other = tmp_path / "a.h5", tmp_path / "other" / "a.h5"
    Archive(path).append([tiny_entry(1)])
    Archive(path).append([tiny_entry(2)])
    Archive(other).append([_scene(1, "tiny")])  # the same scene and texts, other forces: it verifies
    a = Archive(path)
    assert np.array_equal(a.read(2).truth["wall_force"], tiny_entry(1).truth["wall_force"])
    replacement = tmp_path / "replacement.h5"
    shutil.copyfile(_part(other), replacement)
    os.replace(replacement, _part(path))  # a new file at the part's path: a new version
    assert np.array_equal(a.read(2).truth["wall_force"], tiny_entry(1).truth["wall_force"] + 1)
    shutil.copyfile(_part(other), replacement)
    _flip_in_place(replacement, "shared/scene_tiny/forces/wall_force")
    os.replace(replacement, _part(path))
    with pytest.raises(InstrumentError, match="shot 2: shared/scene_tiny/forces/wall_force: damaged"):
        a.read(2)
    assert a.read(2, with_truth=False).truth is None  # a read without the truth does not read it


def test_the_forces_of_the_last_forces_kept_groups_only_are_kept(tmp_path):
    path = tmp_path / "a.h5"
    keys = [f"s{k}" for k in range(FORCES_KEPT + 1)]
    for seed, key in enumerate(keys, 1):
        Archive(path).append([_scene(seed, key)])  # shot n: scene s(n-1), in part n
    a = Archive(path)
    for shot in range(1, len(keys) + 1):
        assert np.array_equal(a.read(shot).truth["wall_force"], tiny_entry(1).truth["wall_force"] + shot)
    for shot, key in enumerate(keys, 1):
        _flip_in_place(_part(path, shot), f"shared/scene_{key}/forces/wall_force")
    for shot in range(2, len(keys) + 1):  # the last FORCES_KEPT: kept, not read again
        assert np.array_equal(a.read(shot).truth["wall_force"], tiny_entry(1).truth["wall_force"] + shot)
    with pytest.raises(InstrumentError, match="shot 1: unreadable"):
        a.read(1)  # the first group's forces were let go: read from the file again


def test_layout_2_reads_its_truth_once_per_version_of_the_file(tmp_path):
    path = tmp_path / "old.h5"
    shutil.copyfile(OLD, path)
    a = Archive(path)
    first = a.read(1).truth
    _flip_in_place(path, "shared/scene_tiny/forces/" + sorted(first)[0])
    assert all(np.array_equal(a.read(1).truth[k], first[k]) for k in first)  # the same version: not read again
    Archive(path).append([tiny_entry(5, truth=False)])  # layout 2: the whole file copied, a new version
    with pytest.raises(InstrumentError, match="shot 1: shared/scene_tiny/forces/.*: damaged"):
        a.read(1)


def test_the_first_read_of_a_version_reads_each_truth_force_once(tmp_path, monkeypatch):
    path = tmp_path / "a.h5"
    Archive(path).append([tiny_entry(1)])
    Archive(path).append([tiny_entry(2)])
    reads: list = []
    read_value = values.dataset_value

    def counted(dataset_id):
        reads.append(h5py.h5i.get_name(dataset_id).decode())
        return read_value(dataset_id)

    def counted_item(dataset, key):
        reads.append(dataset.name)
        return get_item(dataset, key)

    get_item = h5py.Dataset.__getitem__
    monkeypatch.setattr(values, "dataset_value", counted)  # how the reader reads a value
    monkeypatch.setattr(digest, "dataset_value", counted)  # how the check reads one
    monkeypatch.setattr(h5py.Dataset, "__getitem__", counted_item)  # and any read through h5py's own objects
    a = Archive(path)
    truth = a.read(2).truth
    forces = sorted(r for r in reads if "/forces/" in r and not r.endswith("/time"))
    assert forces == sorted(f"/shared/scene_tiny/forces/{k}" for k in truth)  # each once, not twice
    reads.clear()
    a.read(1)
    assert not [r for r in reads if "/forces/" in r]  # the same version: kept


def test_a_read_that_skips_the_checksums_takes_the_truth_kept(tmp_path):
    path = tmp_path / "a.h5"
    Archive(path).append([tiny_entry(1)])
    Archive(path).append([tiny_entry(2)])
    a = Archive(path)
    a.read(1)
    _flip_in_place(_part(path), "shared/scene_tiny/forces/wall_force")
    for shot in (2, 1):  # the forces the checked read kept: the damaged chunk never met
        assert np.array_equal(a.read(shot, verify=False).truth["wall_force"], tiny_entry(1).truth["wall_force"])
    with pytest.raises(InstrumentError, match="shot 2: unreadable"):
        Archive(path).read(2, verify=False)  # a new reader reads them from the file
    b = Archive(path)
    assert b.read(2, verify=False, with_truth=False).truth is None
    with pytest.raises(InstrumentError, match="shot 2: shared/scene_tiny/forces/wall_force: damaged"):
        b.read(2)  # the checked read finds the damage the unchecked one did not read


def test_a_checked_read_checks_the_forces_an_unchecked_read_kept(tmp_path):
    path = tmp_path / "a.h5"
    Archive(path).append([tiny_entry(1)])
    Archive(path).append([tiny_entry(2)])
    a = Archive(path)
    a.read(2, with_truth=False)  # the group checked (its forces not read)
    a.read(2, verify=False)  # the forces read unchecked, and kept
    _flip_in_place(_part(path), "shared/scene_tiny/forces/wall_force")
    with pytest.raises(InstrumentError, match="shot 2: unreadable"):
        a.read(2)  # not given the unchecked forces: it reads the file and meets the damage
