"""Random byte flips over a small archive: every flip that changes what a reader sees
(h5py, or xarray through h5netcdf) is found by ``Archive.verify`` and named; none makes
verify raise, and a later append either works or refuses in one line."""
import numpy as np
import pytest

from instruments.archive import Archive, Entry
from instruments.archive.facts import GaugeFact, ShotFacts
from instruments.errors import InstrumentError
from instruments.records import Preamble, ScopeRecord, Waveform

FLIPS = 240  # 120 left three damage paths of append and verify unreached (coverage, measured)


def tiny_entry(seed: int, truth: bool = True, n: int = 96) -> Entry:
    """A small shot: two int8 channels and (``truth``) two shared truth arrays."""
    rng = np.random.default_rng(seed)
    p = Preamble(points=n, x_increment=1e-6, x_zero=-1e-5, trigger_index=10, y_multiplier=0.01, y_offset=0.0,
                 y_zero=0.0, point_format="ENV" if seed == 3 else "Y")
    waves = {c: Waveform(c, p, codes=rng.integers(-100, 100, n).astype(np.int8)) for c in ("CH1", "CH2")}
    facts = ShotFacts(1e-6, {"upper": GaugeFact(3, "CH1", 0.01, 0.1, 0.2)}, None, None, {"probe": {"gain": 1.0}},
                      1e-5, {"method": "synthetic"})
    forces = {"upper_average_force": np.linspace(0, 1, 48), "wall_force": np.linspace(1, 0, 48)}
    return Entry(ScopeRecord(waves, True), truth, seed if truth else None, "tiny" if truth else "",
                 "[scene]\nname = 'tiny'\n" if truth else "",
                 {"probe": "tiny"} if truth else {"source_files": ["a.isf"]},
                 forces if truth else None, facts if truth else None, "tiny" if truth else None,
                 "2026-01-01T00:00:00+00:00", "0.9")


def h5py_view(path) -> dict:
    """Everything h5py reads from the archive, its external links followed (layout 3's
    part files): {path or path@attribute: value as bytes}; a read that fails is a value too."""
    import h5py

    view = {}
    try:
        with h5py.File(path, "r") as f:
            def visit(name, obj):
                try:
                    view[f"/{name}"] = _bytes(obj[()]) if isinstance(obj, h5py.Dataset) else b"group"
                except Exception as exc:  # noqa: BLE001
                    view[f"/{name}"] = f"error {type(exc).__name__}".encode()
                try:
                    for k in obj.attrs:
                        view[f"/{name}@{k}"] = _bytes(obj.attrs[k]) if k not in ("DIMENSION_LIST", "REFERENCE_LIST") \
                            else repr([[f[r].name for r in row] if k == "DIMENSION_LIST" else f[row[0]].name
                                       for row in obj.attrs[k]]).encode()
                except Exception as exc:  # noqa: BLE001
                    view[f"/{name}@"] = f"error {type(exc).__name__}".encode()
            for k in f.attrs:
                view[f"/@{k}"] = _bytes(f.attrs[k])
            f.visititems(visit)
            for top in ("", "shared/"):  # visititems does not follow external links: each link's tree
                try:
                    names = list(f[top] if top else f)
                except Exception:  # noqa: BLE001 - no /shared, or an unreadable one: the visit above tells
                    names = []
                for name in names:
                    try:
                        obj = f[top + name]
                        visit(top + name, obj)
                        if isinstance(obj, h5py.Group):
                            obj.visititems(lambda n, o, p=top + name: visit(f"{p}/{n}", o))
                    except Exception as exc:  # noqa: BLE001
                        view[f"/{top}{name}"] = f"error {type(exc).__name__}".encode()
    except Exception as exc:  # noqa: BLE001
        view["<file>"] = f"error {type(exc).__name__}".encode()
    return view


def xarray_view(path) -> dict:
    """Everything xarray reads through h5netcdf (CF decoding, dimension scales), unchecked."""
    import xarray as xr

    view = {}
    try:
        tree = xr.open_datatree(path, engine="h5netcdf")
        for node in tree.subtree:
            for k, v in node.attrs.items():
                view[f"xr:{node.path}@{k}"] = _bytes(v)
            for name, var in node.variables.items():
                view[f"xr:{node.path}/{name}"] = _bytes(var.values)
                for k, v in var.attrs.items():
                    view[f"xr:{node.path}/{name}@{k}"] = _bytes(v)
    except Exception as exc:  # noqa: BLE001
        view["xr:<file>"] = f"error {type(exc).__name__}".encode()
    return view


def _bytes(v) -> bytes:
    if isinstance(v, (bytes, str)):
        return v.encode() if isinstance(v, str) else v
    v = np.asarray(v)
    if v.dtype.kind == "O":
        return repr(v.tolist()).encode()
    return v.dtype.str.encode() + repr(v.shape).encode() + v.tobytes()


def _named(changed: set, bad: list, path) -> bool:
    """Does some row of the report name one of the changed items (or a group that holds it)?"""
    wheres = [b["where"] for b in bad]
    for c in changed:
        item = c.removeprefix("xr:")
        if item.endswith("<file>") and any(w in (str(path), "/") for w in wheres):
            return True
        for w in wheres:
            if w.startswith("/") and (item.startswith(w) or w.startswith(item.split("@")[0])):
                return True
    # xarray names a shared group through a shot's link: the shot's truth/forces
    return any("truth/forces" in c and any("/shared/" in w for w in wheres) for c in changed)


def archive_files(path) -> list:
    """The files of an archive (layout 3: its master, then its part files), relative to its folder."""
    return [path.name] + sorted(str(p.relative_to(path.parent)) for p in path.parent.glob(path.name + ".d/*.h5"))


@pytest.fixture(scope="module")
def pristine(tmp_path_factory):
    path = tmp_path_factory.mktemp("flips") / "f.h5"
    a = Archive(path)
    a.append([tiny_entry(1), tiny_entry(2)])
    a.append([tiny_entry(3), tiny_entry(4, truth=False)])
    assert a.verify() == {"shots": 4, "ok": 4, "bad": []}
    return {n: (path.parent / n).read_bytes() for n in archive_files(path)}, h5py_view(path), xarray_view(path)


def test_random_byte_flips_are_found_and_named_and_never_crash(pristine, tmp_path):
    files, view, xview = pristine
    data = b"".join(files.values())  # the archive's bytes: its master, then its parts
    starts = np.cumsum([0] + [len(b) for b in files.values()])
    rng = np.random.default_rng(20261123)
    offsets = rng.integers(0, len(data), FLIPS)
    masks = rng.integers(1, 256, FLIPS)
    path = tmp_path / "f.h5"
    seen, unnamed, appended, refused = 0, [], 0, 0
    assert xview["xr:/shot_000001/data/CH1"]  # xarray opens the whole pristine file
    for offset, mask in zip(offsets, masks):
        damaged = bytearray(data)
        damaged[offset] ^= int(mask)
        for p in path.parent.glob(path.name + ".d/*.h5"):
            p.unlink()  # the part of the last append after a flip
        for (name, _), start, end in zip(files.items(), starts, starts[1:]):
            (tmp_path / name).parent.mkdir(exist_ok=True)
            (tmp_path / name).write_bytes(bytes(damaged[start:end]))
        now = h5py_view(path)
        changed = {k for k in set(view) | set(now) if view.get(k) != now.get(k)}
        if not changed:  # xarray reads through h5py: asked where h5py sees no change
            now = xarray_view(path)
            changed = {k for k in set(xview) | set(now) if xview.get(k) != now.get(k)}
        report = Archive(path).verify()  # never raises
        if changed:
            seen += 1
            if not report["bad"] or not _named(changed, report["bad"], path):
                unnamed.append((int(offset), sorted(changed)[:3], report["bad"][:2]))
        try:
            Archive(path).append([tiny_entry(5)])
            appended += 1
        except InstrumentError as exc:  # a refusal is one line naming the archive
            assert str(path) in str(exc) and "\n" not in str(exc)
            refused += 1
    print(f"{FLIPS} flips: {seen} changed what a reader sees, {appended} appended after, {refused} refused")
    assert unnamed == []
    assert seen >= FLIPS // 4 and appended + refused == FLIPS  # most flips change what readers see


@pytest.mark.parametrize("item", ["forces/wall_force", "settings"])
def test_a_shot_read_without_its_truth_ignores_only_damaged_truth(tmp_path, item):
    # the analysis reads a shot's scope records, facts and settings, not its truth's
    # forces: damaged shared forces do not stop it (a read with the truth still refuses);
    # damaged shared settings do
    import h5py

    path = tmp_path / "a.h5"
    Archive(path).append([tiny_entry(1)])
    with h5py.File(path, "r+") as f:
        (key,) = list(f["shared"])
        d = f[f"shared/{key}/{item}"]
        if d.dtype.kind == "f":
            d[5] = d[5] + 1.0
        else:
            d[()] = '{"probe": "tinY"}'
    with pytest.raises(InstrumentError, match=f"shot 1: shared/{key}/{item}: damaged"):
        Archive(path).read(1)
    if item == "settings":
        with pytest.raises(InstrumentError, match=f"shared/{key}/settings: damaged"):
            Archive(path).read(1, with_truth=False)
    else:
        archive = Archive(path)
        e = archive.read(1, with_truth=False)
        assert e.truth is None
        assert np.array_equal(e.record.waveforms["CH1"].codes, tiny_entry(1).record.waveforms["CH1"].codes)
        with pytest.raises(InstrumentError, match="forces/wall_force: damaged"):
            archive.read(1)  # the same Archive: the shared group was not remembered as sound


@pytest.mark.parametrize("item", ["@metadata", "data/CH2", "data/time", "data/CH2@units"])
def test_a_read_checks_what_it_returns_and_verify_checks_the_rest(tmp_path, item):
    # a read refuses a shot whose returned items (codes; preambles and the rest in metadata) are damaged; the
    # time axis and the plot's units, which a read does not return (it computes them from the
    # preambles), are left to verify
    import h5py

    path = tmp_path / "a.h5"
    Archive(path).append([tiny_entry(1), tiny_entry(2)])
    with h5py.File(path, "r+") as f:  # h5py follows the master's link into the part file
        name, _, attr = item.partition("@")
        obj = f[f"shot_000002/{name}"]
        if attr:
            obj.attrs[attr] = obj.attrs[attr].replace('"y_zero": 0.0', '"y_zero": 0.5') if attr == "metadata" else "mV"
        elif obj.dtype.kind == "f":
            obj[5] = obj[5] + 1.0
        else:
            obj[()] = 7
    bad = Archive(path).verify()["bad"]
    # the shots of one transaction share their time axis (one dataset, hard-linked): both see it damaged
    assert [b["shot"] for b in bad] == ([1, 2] if item == "data/time" else [2])
    assert bad[-1]["where"] == f"/shot_000002/{item}"
    assert Archive(path).read(1).seed == 1
    if item in ("data/time", "data/CH2@units"):
        back = Archive(path).read(2)
        assert np.array_equal(back.record.waveforms["CH2"].codes, tiny_entry(2).record.waveforms["CH2"].codes)
    else:
        with pytest.raises(InstrumentError, match=f"shot 2: {'attribute ' if attr else ''}{item}: damaged"):
            Archive(path).read(2)


@pytest.mark.parametrize("damaged", [1, 2])
def test_a_time_axis_its_part_s_shots_share_is_judged_in_each_part(tmp_path, damaged):
    # verify reads a dataset that several shots link to (a part's time axis) once per part
    # file, not once per shot: damage in one part's axis names that part's shots and only
    # those, though the two parts are alike and their axes lie at the same address
    import h5py

    path = tmp_path / "a.h5"
    a = Archive(path)
    a.append([tiny_entry(1, truth=False), tiny_entry(2, truth=False)])
    a.append([tiny_entry(5, truth=False), tiny_entry(6, truth=False)])
    with h5py.File(path, "r+") as f:
        first, second = f["shot_000001/data/time"], f["shot_000003/data/time"]
        assert h5py.h5o.get_info(first.id).addr == h5py.h5o.get_info(second.id).addr  # in two part files
        assert first.file.filename != second.file.filename
        axis = first if damaged == 1 else second
        axis[5] = axis[5] + 1
    report = a.verify()
    shots = [1, 2] if damaged == 1 else [3, 4]
    assert [b["shot"] for b in report["bad"]] == shots and report["ok"] == 2
    assert {b["where"] for b in report["bad"]} == {f"/shot_{i:06d}/data/time" for i in shots}
