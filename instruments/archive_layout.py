"""How one shot lies in the HDF5 shot archive (NeXus-style): the Entry a shot is written
from and read back into, its SHA-256, and the writer and reader of one NXentry.

One NXentry per shot (``/shot_000001``, ...)::

    shot_000001/            NXentry; attribute "shot": shot_id, seed (-1: none), simulated,
                            triggered, scene, start_time (UTC), project_version, sha256 (of
                            the raw codes and their scaling), no_trigger_reason
      scene_text, settings  the scene as fired (TOML) and every part's settings (JSON, SI)
      instrument/oscilloscope/
                            NXcollection; CHn: raw ADC codes (int8/int16) with CF units,
                            scale_factor, add_offset (-> V), or volts (float64) from a
                            file that holds volts only; attribute "preamble": a table of
                            each channel's Tektronix scaling, trigger index, over-range flag
      data/                 NXdata, the default plot: the same CHn (hard links) and time
                            (int32 sample index, CF-scaled to s from the trigger), attached
                            as a dimension scale: opens with xarray's h5netcdf engine
      truth/                ground truth (virtual shots): per-shot draws in the attribute
                            "facts"; forces/ is a hard link to the noise-free force arrays (N)
      analysis/             results, added by the analysis when there are some
    shared/<key>/           what all shots of one scene share, stored once: scene_text,
                            settings, forces/

The scope records and the truth's forces are chunked, gzip-compressed (level 1, shuffle)
and carry the fletcher32 checksum, and each entry's sha256 of its raw data is checked again
on read; the time index, the settings and the scene text carry no checksum yet.
"""
from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass, field
from datetime import datetime, timezone
from typing import TYPE_CHECKING

import numpy as np

from .errors import InstrumentError
from .facts import ShotFacts
from .records import Preamble, ScopeRecord, Waveform

if TYPE_CHECKING:  # h5py itself is imported where a file is opened: Entry alone does not need it
    import h5py

LAYOUT = """One NXentry per shot (shot_NNNNNN). Its attribute 'shot' holds shot_id, seed
(-1: none), simulated, triggered, scene, start_time (UTC, ISO 8601), project_version and the
sha256 of the raw codes with their scaling. scene_text: the scene file as fired; settings:
JSON of every part's settings in SI units. instrument/oscilloscope/CHn: raw ADC codes; the
group attribute 'preamble' is a table of each channel's Tektronix scaling: volts = y_zero +
y_multiplier * (codes - y_offset), time = x_zero + x_increment * n (s from the trigger,
x_zero is the first sample's time). data/: the default plot: the same codes (hard links)
with CF scale_factor/add_offset giving volts, and time (int32 sample index, CF-scaled to s).
truth/: per-shot draws as JSON in the attribute 'facts', and forces/: noise-free forces (N)
on the solver grid, stored once per scene under shared/. All datasets but the time index
are gzip-compressed with the fletcher32 checksum."""
COMPRESSION = dict(compression="gzip", compression_opts=1, shuffle=True, fletcher32=True)
_PREAMBLE_FLOATS = ("x_increment", "x_zero", "y_multiplier", "y_offset", "y_zero")


@dataclass(eq=False)
class Entry:
    """One shot as the archive stores it: plain data, real or virtual.

    truth: name -> array (N) of ground-truth forces; facts: the virtual shot's ShotFacts
    (draws, gauge positions, ...; None for a real shot); truth_key: shots with equal keys
    share the truth arrays.
    """

    record: ScopeRecord
    simulated: bool
    seed: int | None = None
    scene: str = ""
    scene_text: str = ""
    settings: dict = field(default_factory=dict)
    truth: dict | None = None
    facts: ShotFacts | None = None
    truth_key: str | None = None
    start_time: str = ""
    project_version: str = ""
    shot_id: int | None = None  # set when read back


def raw_values(w: Waveform) -> np.ndarray:
    """What a channel stores: its raw codes, or its volts (float64) where a file held
    volts only (CSV)."""
    return w.codes if w.codes is not None else np.asarray(w.samples, dtype=np.float64)


def raw_digest(record: ScopeRecord) -> str:
    """SHA-256 over each channel's name, scaling, point format (when not plain samples) and
    raw codes (or volts), in channel order."""
    h = hashlib.sha256()
    for ch in sorted(record.waveforms):
        w = record.waveforms[ch]
        p = w.preamble
        h.update(ch.encode())
        h.update(json.dumps([p.points, p.trigger_index] + [getattr(p, k) for k in _PREAMBLE_FLOATS]).encode())
        if p.point_format != "Y":  # sample records hash as they always did
            h.update(p.point_format.encode())
        h.update(np.ascontiguousarray(raw_values(w)).tobytes())
    return h.hexdigest()


def write_entry(f: h5py.File, shot_id: int, e: Entry, checked: set):
    """Write one NXentry; ``checked`` holds the shared keys already verified this transaction."""
    facts = _facts_json(e, f"shot {shot_id}: facts") if e.truth is not None else None
    g = f.create_group(f"shot_{shot_id:06d}")
    g.attrs.update({"NX_class": "NXentry", "default": "data", "shot": _shot_attr(shot_id, e)})
    key = e.truth_key or f"shot_{shot_id:06d}"
    shared = f.require_group("shared").require_group(key)
    if key not in checked:
        for name, text in (("scene_text", e.scene_text),
                           ("settings", json.dumps(e.settings, default=_jsonable, sort_keys=True))):
            if name not in shared:
                shared.create_dataset(name, data=text)
            elif shared[name][()].decode() != text:
                raise InstrumentError(f"shared key {key!r}: {name} differs between shots")
        checked.add(key)
    g["scene_text"] = shared["scene_text"]
    g["settings"] = shared["settings"]
    instrument = g.create_group("instrument")
    instrument.attrs["NX_class"] = "NXinstrument"
    scope = instrument.create_group("oscilloscope")
    scope.attrs["NX_class"] = "NXcollection"
    data = g.create_group("data")
    chans = sorted(e.record.waveforms)
    data.attrs.update({"NX_class": "NXdata", "signal": chans[0] if chans else "", "axes": ["time"]})
    scope.attrs["preamble"] = _preamble_table(e.record)
    for ch in chans:
        w = e.record.waveforms[ch]
        p = w.preamble
        values = raw_values(w)
        d = scope.create_dataset(ch, data=values, **_chunks(values))
        d.attrs["units"] = p.y_unit
        if w.codes is not None:  # CF scaling of the codes to volts
            d.attrs.update({"scale_factor": p.y_multiplier, "add_offset": p.y_zero - p.y_multiplier * p.y_offset})
        data[ch] = d  # hard link: the plottable data are the raw codes
        d.dims[0].attach_scale(_time_axis(data, p))
    if e.truth is not None:
        tg = g.create_group("truth")
        tg.attrs.update({"NX_class": "NXcollection",
                         "facts": facts})
        if "forces" not in shared:
            forces = shared.create_group("forces")
            for name, arr in e.truth.items():
                forces.create_dataset(name, data=np.asarray(arr), **_chunks(arr)).attrs["units"] = "N"
        tg["forces"] = shared["forces"]  # one hard link to the arrays stored once per key


def _facts_json(e: Entry, where: str) -> str:
    """The facts as stored (JSON with their version; "{}": none), checked as a reader will
    check them: the archive refuses to write facts it would refuse to read."""
    if e.facts is None:
        return "{}"
    if not isinstance(e.facts, ShotFacts):
        raise InstrumentError(f"{where} = {type(e.facts).__name__}: expected ShotFacts (instruments.facts) or None")
    text = json.dumps(e.facts.to_dict(), default=_jsonable)
    ShotFacts.from_dict(json.loads(text), where)
    return text


def _shot_attr(shot_id: int, e: Entry) -> np.ndarray:
    """The shot's facts as one self-describing compound attribute."""
    start = e.start_time or datetime.now(timezone.utc).isoformat()
    reason = e.record.reason or ""
    fields = [("shot_id", "<i8", shot_id), ("seed", "<i8", -1 if e.seed is None else int(e.seed)),
              ("simulated", "u1", int(e.simulated)), ("triggered", "u1", int(e.record.triggered)),
              ("scene", f"S{max(1, len(e.scene.encode()))}", e.scene.encode()),
              ("start_time", f"S{len(start)}", start.encode()),
              ("project_version", f"S{max(1, len(e.project_version))}", e.project_version.encode()),
              ("sha256", "S64", raw_digest(e.record).encode()),
              ("no_trigger_reason", f"S{max(1, len(reason.encode()))}", reason.encode())]
    return np.array(tuple(v for _, _, v in fields), dtype=[(n, t) for n, t, _ in fields])


def _preamble_table(record: ScopeRecord) -> np.ndarray:
    """Every channel's Tektronix scaling in one compound table, a row per channel."""
    chans = sorted(record.waveforms)
    rows = []
    for ch in chans:
        w = record.waveforms[ch]
        p = w.preamble
        rows.append((ch.encode(), p.points, p.trigger_index, p.byte_count, p.x_increment, p.x_zero,
                     p.y_multiplier, p.y_offset, p.y_zero, p.x_unit.encode(), p.y_unit.encode(),
                     int(w.overrange), p.point_format.encode(), p.waveform_id.encode(),
                     json.dumps(p.extra, default=_jsonable).encode()))
    width = [max([len(r[i]) for r in rows] + [1]) for i in (0, 13, 14)]
    dtype = np.dtype([("channel", f"S{width[0]}")] + _PREAMBLE_FIELDS +
                     [("waveform_id", f"S{width[1]}"), ("extra", f"S{width[2]}")])
    return np.array(rows, dtype=dtype)


_PREAMBLE_FIELDS = [("points", "<i8"), ("trigger_index", "<i8"), ("byte_count", "<i4"),
                    ("x_increment", "<f8"), ("x_zero", "<f8"), ("y_multiplier", "<f8"),
                    ("y_offset", "<f8"), ("y_zero", "<f8"), ("x_unit", "S8"), ("y_unit", "S8"),
                    ("overrange", "u1"), ("point_format", "S4")]


def _time_axis(data: h5py.Group, p: Preamble) -> h5py.Dataset:
    """The time axis for a channel's time base: "time" for the first, "time_2"... after."""
    n = 1
    while True:
        name = "time" if n == 1 else f"time_{n}"
        if name not in data:
            t = data.create_dataset(name, data=np.arange(p.points, dtype=np.int32))  # an index
            t.attrs.update({"units": "s", "scale_factor": p.x_increment, "add_offset": p.x_zero})
            t.make_scale(name)
            return t
        t = data[name]
        if (t.shape[0], t.attrs["scale_factor"], t.attrs["add_offset"]) == (p.points, p.x_increment, p.x_zero):
            return t
        n += 1


def _chunks(arr) -> dict:
    n = int(np.asarray(arr).size)
    return dict(chunks=(max(1, min(n, 65536)),), **COMPRESSION) if n else {}


def read_entry(g: h5py.Group, verify: bool, path, with_truth: bool = True) -> Entry:
    shot = g.attrs["shot"]
    waves = {}
    scope = g["instrument/oscilloscope"]
    table = scope.attrs["preamble"] if len(scope) else []
    for pa in table:
        ch = pa["channel"].decode()
        d = scope[ch]
        pre = Preamble(points=int(pa["points"]), trigger_index=int(pa["trigger_index"]),
                       byte_count=int(pa["byte_count"]), x_unit=pa["x_unit"].decode(),
                       y_unit=pa["y_unit"].decode(), waveform_id=pa["waveform_id"].decode(),
                       point_format=pa["point_format"].decode() if "point_format" in pa.dtype.names else "Y",
                       extra=json.loads(pa["extra"].decode()),
                       **{k: float(pa[k]) for k in _PREAMBLE_FLOATS})
        values = d[()]
        if values.dtype.kind == "f":  # volts from a file that held volts only
            waves[ch] = Waveform(ch, pre, samples=values, overrange=bool(pa["overrange"]))
        else:
            waves[ch] = Waveform(ch, pre, codes=values, overrange=bool(pa["overrange"]))
    record = ScopeRecord(waves, bool(shot["triggered"]), shot["no_trigger_reason"].decode() or None)
    if verify and raw_digest(record) != shot["sha256"].decode():
        raise InstrumentError(f"{path}: shot {int(shot['shot_id'])}: sha256 of the raw data does not match")
    truth, facts = None, None
    if "truth" in g:
        stored = json.loads(g["truth"].attrs["facts"])
        facts = ShotFacts.from_dict(stored, f"{path}: shot {int(shot['shot_id'])}: facts") if stored else None
        if with_truth:
            truth = {k: v[()] for k, v in g["truth/forces"].items()}
    seed = int(shot["seed"])
    return Entry(record, bool(shot["simulated"]), None if seed < 0 else seed, shot["scene"].decode(),
                 g["scene_text"][()].decode(), json.loads(g["settings"][()]), truth, facts, None,
                 shot["start_time"].decode(), shot["project_version"].decode(), int(shot["shot_id"]))


def _jsonable(x):
    if isinstance(x, np.generic):
        return x.item()
    if isinstance(x, (tuple, set)):
        return list(x)
    return str(x)
