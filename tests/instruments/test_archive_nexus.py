"""The archive is NeXus that a validator accepts (nexusformat's, as ``nxcheck`` runs it),
plus the rules the validators do not all check: valid names, NX_class on every group,
title and start_time, signal/axes/units, volts and seconds in data/ (layout 4: the codes and
the sample index, CF-packed), the truth's own time."""
import re

import h5py
import numpy as np
import pytest
from test_archive_flips import tiny_entry

from instruments.archive import Archive
from instruments.records import Preamble, ScopeRecord, Waveform

NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*\Z")


@pytest.fixture(scope="module")
def archive(tmp_path_factory):
    path = tmp_path_factory.mktemp("nexus") / "n.h5"
    p = Preamble(points=50, x_increment=2e-6, x_zero=0.0, trigger_index=0, y_multiplier=1.0, y_offset=0.0, y_zero=0.0)
    two_records = ScopeRecord({c: Waveform(c, p, samples=np.linspace(0, 1, 50)) for c in ("CH1", "CH1#2")}, True)
    real = tiny_entry(9, truth=False)
    Archive(path).append([tiny_entry(1), tiny_entry(3), real, type(real)(two_records, False)])
    return path


def test_nexusformat_validation_finds_no_error(archive):
    validate = pytest.importorskip("nexusformat.nexus.validate")
    warnings, errors = validate.validate_file(str(archive))
    assert errors == 0


def test_names_classes_and_entry_fields(archive):
    with h5py.File(archive, "r") as f:
        groups, names = [f], []
        f.visititems(lambda n, o: (names.append(n.rsplit("/", 1)[-1]),
                                   groups.append(o) if isinstance(o, h5py.Group) else None))
        assert names and all(NAME.match(n) for n in names), [n for n in names if not NAME.match(n)]
        assert all("NX_class" in g.attrs for g in groups), [g.name for g in groups if "NX_class" not in g.attrs]
        for key in (k for k in f if k.startswith("shot_")):
            g = f[key]
            assert g.attrs["NX_class"] == "NXentry" and g["title"][()] and g["start_time"][()]
        shot = f["shot_000001"]
        data = shot["data"]
        assert data.attrs["NX_class"] == "NXdata" and data.attrs["signal"] == "CH1"
        assert list(data.attrs["auxiliary_signals"]) == ["CH2"]  # every other channel, for viewers
        assert list(data.attrs["axes"]) == ["time"]
        # the plot is the raw codes, packed volts (CF: scale_factor, add_offset), against the
        # sample index packed the same way into seconds
        w = tiny_entry(1).record["CH1"]
        ch1, time = data["CH1"], data["time"]
        assert ch1.dtype == np.int8 and ch1.attrs["units"] == "V" and np.array_equal(ch1[()], w.codes)
        volts = ch1[()] * ch1.attrs["scale_factor"] + ch1.attrs["add_offset"]
        assert np.allclose(volts, w.volts(), rtol=1e-12, atol=1e-15)
        assert time.dtype.kind == "u" and time.attrs["units"] == "s"
        seconds = time[()] * time.attrs["scale_factor"] + time.attrs["add_offset"]
        assert seconds[1] - seconds[0] == pytest.approx(1e-6, rel=1e-12)
        assert np.allclose(seconds, w.time(), rtol=1e-12, atol=1e-18)
        forces = shot["truth/forces"]
        assert forces.attrs["NX_class"] == "NXdata" and list(forces.attrs["axes"]) == ["time"]
        assert forces["time"].attrs["units"] == "s" and forces["time"][1] == pytest.approx(1e-6, rel=1e-12)
        assert forces[forces.attrs["signal"]].attrs["units"] == "N"
        assert set(f["shot_000004/data"]) == {"CH1", "CH1_2", "time"}  # the second record of CH1
        assert list(f["shot_000004/data"].attrs["auxiliary_signals"]) == ["CH1_2"]
        assert list(forces.attrs["auxiliary_signals"]) == [n for n in ("upper_average_force", "wall_force")
                                                           if n != forces.attrs["signal"]]


def test_the_auxiliary_signals_are_covered_by_the_digests(archive, tmp_path):
    import shutil

    copy = tmp_path / archive.name  # an archive is its master and its folder of parts, copied together
    shutil.copy(archive, copy)
    shutil.copytree(archive.with_name(archive.name + ".d"), copy.with_name(copy.name + ".d"))
    assert Archive(copy).verify()["bad"] == []
    with h5py.File(copy, "r+") as f:
        f["shot_000001/data"].attrs["auxiliary_signals"] = ["CH3"]
    (bad,) = Archive(copy).verify()["bad"]
    assert bad["shot"] == 1 and bad["where"].endswith("data@auxiliary_signals"), bad


def test_open_datatree_opens_the_whole_archive(archive):
    xr = pytest.importorskip("xarray")
    tree = xr.open_datatree(archive, engine="h5netcdf")
    assert {"shot_000001", "shot_000004", "shared"} <= set(tree.children)
    ch1 = tree["shot_000001/data"]["CH1"]
    assert ch1.dims == ("time",) and ch1.attrs["units"] == "V"
    assert tree["shot_000001/data"]["time"].values[0] == pytest.approx(-1e-5, rel=1e-12)
    back = Archive(archive).read(4).record
    assert back["CH1#2"].channel == "CH1#2" and np.array_equal(back["CH1#2"].volts(), np.linspace(0, 1, 50))
    envelope = Archive(archive).read(2).record["CH1"].preamble  # tiny_entry(3) is an envelope record
    assert envelope.point_format == "ENV" and Archive(archive).read(1).record["CH1"].preamble.point_format == "Y"
