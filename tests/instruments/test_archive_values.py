"""The archive's own reads of HDF5 values (instruments/archive/values.py) give what h5py
gives, item by item, over every dataset and attribute of archives of layouts 2, 3 and 4; a
table of checksums computed either way is the same. And an Archive that keeps its files
open between reads sees each new version of them."""
import shutil
from pathlib import Path

import h5py
import numpy as np
import pytest
from test_archive_flips import tiny_entry

from instruments.archive import Archive, raw_digest
from instruments.archive.hashes import attribute_digest, value_digest
from instruments.archive.values import attribute_names, attribute_value, dataset_value
from instruments.errors import InstrumentError

DATA = Path(__file__).parent / "data"


def _objects(path) -> list:
    with h5py.File(path, "r") as f:
        names = [""]
        f.visit(names.append)
    return names


@pytest.fixture(scope="module")
def files(tmp_path_factory) -> list:
    path = tmp_path_factory.mktemp("values") / "a.h5"
    a = Archive(path)
    a.append([tiny_entry(1), tiny_entry(2), tiny_entry(3, truth=False)])
    a.append([tiny_entry(4)])
    return [path, *sorted(path.parent.glob("a.h5.d/*.h5")), DATA / "layout3.h5",
            *sorted(DATA.glob("layout3.h5.d/*.h5")), DATA / "root_digest_v1.h5"]


def test_values_and_attributes_read_as_h5py_reads_them(files):
    seen = {"datasets": 0, "attributes": 0, "texts": 0}
    for path in files:
        with h5py.File(path, "r") as f:
            for name in _objects(path):
                obj = f[name] if name else f
                assert attribute_names(obj) == sorted(obj.attrs), name
                for key in obj.attrs:
                    if key in ("DIMENSION_LIST", "REFERENCE_LIST"):  # references: digest.py reads them with h5py
                        continue
                    ours, theirs = attribute_value(obj, key), obj.attrs[key]
                    assert type(ours) is type(theirs), (name, key)
                    assert attribute_digest(ours) == attribute_digest(theirs), (name, key)
                    seen["attributes"] += 1
                    seen["texts"] += isinstance(theirs, str)
                if isinstance(obj, h5py.Dataset):
                    ours, theirs = dataset_value(obj.id), obj[()]
                    assert type(ours) is type(theirs) and value_digest(ours) == value_digest(theirs), name
                    if isinstance(theirs, np.ndarray):
                        assert ours.dtype == theirs.dtype and np.array_equal(ours, theirs)
                    seen["datasets"] += 1
    assert seen["datasets"] > 50 and seen["attributes"] > 200 and seen["texts"] > 50, seen
    with h5py.File(files[0], "r") as f, pytest.raises(KeyError, match="nothing"):
        attribute_value(f, "nothing")


def test_an_archive_read_again_sees_a_new_master_and_a_part_replaced_or_removed(tmp_path):
    path = tmp_path / "a.h5"
    reader = Archive(path)
    reader.append([tiny_entry(1)])
    assert reader.read(1).seed == 1  # the master and the part now held open by `reader`
    Archive(path).append([tiny_entry(2)])  # another writer puts a new master in place
    assert reader.read(2).seed == 2 and reader.read(1).seed == 1
    part = path.parent / "a.h5.d" / "shots_000001.h5"
    shutil.copyfile(part, tmp_path / "kept.h5")
    part.unlink()
    with pytest.raises(InstrumentError, match="shot 1: unreadable"):
        reader.read(1)
    damaged = bytearray((tmp_path / "kept.h5").read_bytes())
    at = bytes(damaged).index(tiny_entry(1).record.waveforms["CH1"].codes.tobytes())
    damaged[at] ^= 0x40  # a byte of CH1's codes in a copy put in the part's place: a new file
    part.write_bytes(bytes(damaged))
    with pytest.raises(InstrumentError, match="shot 1: .*data/CH1: damaged"):
        reader.read(1)
    assert reader.read(2).seed == 2


def _open_under(folder: Path) -> list:
    """The HDF5 files this process holds open under ``folder``."""
    ids = h5py.h5f.get_obj_ids(h5py.h5f.OBJ_ALL, h5py.h5f.OBJ_FILE)
    return [i.name for i in ids if Path(i.name.decode()).is_relative_to(folder)]


def test_close_closes_the_files_a_read_kept_open_and_a_later_read_opens_them_again(tmp_path):
    path = tmp_path / "a.h5"
    with Archive(path) as a:
        a.append([tiny_entry(1), tiny_entry(2)])
        a.append([tiny_entry(3)])
        first = a.read(1)
        a.read(3)
        assert len(_open_under(tmp_path)) >= 2  # the master and the parts of shots 1 and 3, kept for the next read
    assert _open_under(tmp_path) == []
    again = a.read(1)  # closed, then read: opened again
    assert raw_digest(again.record) == raw_digest(first.record)
    a.close()
    assert _open_under(tmp_path) == []
