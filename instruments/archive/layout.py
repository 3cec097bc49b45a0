"""How one shot lies in the HDF5 shot archive (NeXus): the Entry a shot is written from
and read back into, the SHA-256 of its raw data, and the writer and reader of one NXentry.

The layout (version 2; ``LAYOUT`` below, also stored in the file) is NeXus: valid names,
NX_class on every group, ``title`` and ``start_time`` on every entry, signal/axes/units on
every NXdata, volts and seconds as floats in ``data/``. Every array dataset is chunked with
the fletcher32 checksum; every group's tree (values and attributes) is in its table of
SHA-256 checksums (instruments/archive/digest.py).
"""
from __future__ import annotations

import hashlib
import json
import re
from dataclasses import asdict, dataclass, field
from datetime import datetime, timezone
from typing import TYPE_CHECKING

import numpy as np

from ..errors import InstrumentError
from ..records import Preamble, ScopeRecord, Waveform
from .digest import address, seal, value_digest
from .facts import ShotFacts

if TYPE_CHECKING:  # h5py itself is imported where a file is opened: Entry alone does not need it
    import h5py

LAYOUT_VERSION = 2
LAYOUT = """Layout version 2 (NeXus). One NXentry per shot (shot_NNNNNN), fields: title,
start_time (ISO 8601; its attribute 'source' says what the time is), file_modification_time
(imported files without an acquisition time), scene, seed (virtual shots), simulated,
triggered, no_trigger_reason, program_name (@version), raw_sha256 (of the raw codes and
their scaling), scene_text (TOML as fired), settings (JSON, SI). instrument/oscilloscope/CHn:
the raw ADC codes (units 'counts'; volts where a file held volts only) on the dimension
'sample', the attribute 'preamble' is the channel's Tektronix scaling (JSON): volts = y_zero +
y_multiplier * (codes - y_offset), time = x_zero + x_increment * n (s from the trigger).
data/ (NXdata, the default plot): CHn in volts (float64) against time (float64, s); the
first channel is its signal, the others its auxiliary_signals.
truth/ (virtual shots): facts (JSON) and forces/ (NXdata): the noise-free forces (N) against
their own time (s), stored once per scene under shared/ and hard-linked. Every array is
chunked with fletcher32; each entry's and each shared group's 'checksums' table holds the
SHA-256 of every dataset and attribute, and its attribute 'sha256' that of the table."""
COMPRESSION = dict(compression="gzip", compression_opts=1, shuffle=True, fletcher32=True)
NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*\Z")  # a valid NeXus name
_PREAMBLE_FLOATS = ("x_increment", "x_zero", "y_multiplier", "y_offset", "y_zero")


@dataclass(eq=False)
class Entry:
    """One shot as the archive stores it: plain data, real or virtual.

    truth: name (a NeXus name: letters, digits, '_') -> array (N) of ground-truth forces;
    facts: the virtual shot's ShotFacts (None for a real shot); truth_key: shots with equal
    keys share the truth arrays. start_time: ISO 8601 (UTC; "" = when written);
    start_time_source: what that time is; file_modification_time: for an imported file
    without an acquisition time; title: "" = made from the scene and seed or the files.
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
    start_time_source: str = ""
    file_modification_time: str = ""
    title: str = ""


def raw_values(w: Waveform) -> np.ndarray:
    """What a channel stores: its raw codes, or its volts (float64) where a file held
    volts only (CSV)."""
    return w.codes if w.codes is not None else np.asarray(w.samples, dtype=np.float64)


def raw_digest(record: ScopeRecord) -> str:
    """SHA-256 over each channel's name, scaling, point format (when not "Y") and raw codes
    (or volts), in channel order."""
    h = hashlib.sha256()
    for ch in sorted(record.waveforms):
        w = record.waveforms[ch]
        p = w.preamble
        h.update(ch.encode())
        h.update(json.dumps([p.points, p.trigger_index] + [getattr(p, k) for k in _PREAMBLE_FLOATS]).encode())
        if p.point_format != "Y":
            h.update(p.point_format.encode())
        h.update(np.ascontiguousarray(raw_values(w)).tobytes())
    return h.hexdigest()


def shared_name(e: Entry, shot_id: int) -> str:
    """The shared group of an entry's scene (a valid NeXus name)."""
    return "scene_" + re.sub(r"\W", "_", e.truth_key) if e.truth_key else f"of_shot_{shot_id:06d}"


def write_entry(f: h5py.File, shot_id: int, e: Entry, checked: set, stored: dict | None = None):
    """Write one NXentry, then seal its table of checksums; ``checked`` holds the shared
    groups already compared this transaction. ``stored`` (layout 3, a part file; {key: (part
    file, group)}) names the shared groups an earlier transaction wrote into another part,
    which the entry links to with HDF5 external links; in a part, the axes are dimension
    scales attached to nothing (h5netcdf reads an attached scale's reference in the file it
    opened, the master, where it does not lie; it gives an unattached variable the
    dimension of its length in its group: ``time``)."""
    attach = stored is None
    written: dict = {}  # {address: value_digest} of the datasets this call writes (digest.table)
    put = lambda parent, name, data, **kw: _put(parent, name, data, written, **kw)
    where = f"shot {shot_id}"
    facts = _facts_json(e, f"{where}: facts") if e.truth is not None else None
    key = shared_name(e, shot_id)
    if stored and key in stored:
        members, linked = _stored(key, e, where, checked, *stored[key])
    else:
        shared = _shared(f, key, e, where, checked, attach, written)
        members, linked = shared, {address(o): o.name for o in _objects(shared)}
    g = f.create_group(f"shot_{shot_id:06d}")
    g.attrs.update({"NX_class": "NXentry", "default": "data"})
    start = e.start_time or datetime.now(timezone.utc).isoformat()
    title = e.title or (f"{e.scene} seed {e.seed}" if e.simulated else ", ".join(e.settings.get("source_files", [])))
    put(g, "title", title or f"shot {shot_id}")
    put(g, "start_time", start).attrs["source"] = e.start_time_source or "when the shot was archived"
    if e.file_modification_time:
        put(g, "file_modification_time", e.file_modification_time)
    put(g, "scene", e.scene)
    if e.seed is not None:
        put(g, "seed", np.int64(e.seed))
    put(g, "simulated", np.uint8(e.simulated))
    put(g, "triggered", np.uint8(e.record.triggered))
    if e.record.reason:
        put(g, "no_trigger_reason", e.record.reason)
    put(g, "program_name", "sonic-rig").attrs["version"] = e.project_version
    put(g, "raw_sha256", raw_digest(e.record))
    g["scene_text"] = members["scene_text"]
    g["settings"] = members["settings"]
    _write_record(g, e.record, attach, written)
    if e.truth is not None:
        tg = _group(g, "truth", "NXcollection")
        put(tg, "facts", facts)
        tg["forces"] = members["forces"]  # one link to the arrays stored once per scene
    seal(g, linked, written)


def _texts(e: Entry) -> dict:
    return {"scene_text": e.scene_text, "settings": json.dumps(e.settings, default=_jsonable, sort_keys=True)}


def _compare(s, key: str, e: Entry, where: str):
    for name, text in _texts(e).items():
        if s[name][()].decode() != text:
            raise InstrumentError(f"{where}: shared/{key}/{name} differs from this shot's {name}")


def _stored(key: str, e: Entry, where: str, checked: set, part: str, s) -> tuple:
    """External links to shared/<key> in the part file ``part`` (``s``: that group, read),
    and no linked objects (an external link is its own row in the table)."""
    import h5py

    if key not in checked:
        _compare(s, key, e, where)
        if e.truth is not None and "forces" not in s:
            raise InstrumentError(f"{where}: shared/{key} was stored without truth forces; this shot has them "
                                  "(give it another truth_key)")
        checked.add(key)
    names = ["scene_text", "settings"] + (["forces"] if e.truth is not None else [])
    return {n: h5py.ExternalLink(part, f"/shared/{key}/{n}") for n in names}, {}


def _shared(f, key: str, e: Entry, where: str, checked: set, attach: bool, written: dict):
    """shared/<key>: scene text, settings and truth forces, stored once per scene."""
    root = _group(f, "shared", "NXcollection")
    texts = _texts(e)
    if key in root and key not in checked:
        _compare(root[key], key, e, where)
    s = _group(root, key, "NXcollection")
    fresh = "checksums" not in s
    for name, text in texts.items():
        if name not in s:
            _put(s, name, text, written)
    if e.truth is not None and "forces" not in s:
        _write_forces(s, e, where, attach, written)
        fresh = True
    if fresh:
        if "checksums" in s:
            del s["checksums"]
        seal(s, {}, written)
    checked.add(key)
    return s


def _write_forces(s, e: Entry, where: str, attach: bool, written: dict):
    assert e.truth is not None, "written for a shot with a truth"
    names = list(e.truth)
    bad = [n for n in names if not NAME.match(n) or n in ("time", "sample")]
    if bad:
        raise InstrumentError(f"{where}: truth name {bad[0]!r}: allowed letters, digits and '_', "
                              "not starting with a digit, not 'time' or 'sample'")
    forces = _group(s, "forces", "NXdata")
    n = len(np.asarray(e.truth[names[0]])) if names else 0
    if e.facts is not None:
        axis = _put(forces, "time", np.arange(n) * e.facts.sample_interval_s, written, **_chunks(n))
        axis.attrs["units"] = "s"
    else:  # no facts: no sample interval, an index
        axis = _put(forces, "sample", np.arange(n, dtype=np.int64), written, **_chunks(n))
    axis.make_scale(axis.name.rsplit("/", 1)[1])
    forces.attrs.update({"signal": names[0] if names else "", "axes": [axis.name.rsplit("/", 1)[1]]})
    if len(names) > 1:
        forces.attrs["auxiliary_signals"] = names[1:]
    for name in names:
        d = _put(forces, name, np.asarray(e.truth[name], dtype=np.float64), written, **_chunks(n))
        d.attrs["units"] = "N"
        if attach:
            d.dims[0].attach_scale(axis)


def _write_record(g, record: ScopeRecord, attach: bool, written: dict):
    scope = _group(_group(g, "instrument", "NXinstrument"), "oscilloscope", "NXcollection")
    data = _group(g, "data", "NXdata")
    chans = sorted(record.waveforms)
    data.attrs.update({"signal": chans[0].replace("#", "_") if chans else "", "axes": ["time"]})
    if len(chans) > 1:  # NeXus: the other channels, plotted with the signal by viewers (silx, nexpy)
        data.attrs["auxiliary_signals"] = [ch.replace("#", "_") for ch in chans[1:]]
    for ch in chans:
        if not NAME.match(ch.replace("#", "_")):
            raise InstrumentError(f"channel {ch!r}: allowed letters, digits, '_' and '#'")
        w = record.waveforms[ch]
        p = w.preamble
        name = ch.replace("#", "_")  # "CH1#2", the second record of CH1 in a file: CH1_2
        values = raw_values(w)
        raw = _put(scope, name, values, written, **_chunks(values.size))
        raw.attrs.update({"units": "counts" if w.codes is not None else p.y_unit, "preamble": _preamble_json(w)})
        sample = _axis(scope, "sample", p.points, None, written)
        volts = _put(data, name, np.asarray(w.volts(), dtype=np.float64), written, **_chunks(values.size, False))
        volts.attrs.update({"units": p.y_unit, "long_name": f"{ch} ({p.y_unit})"})
        time = _axis(data, "time", p.points, p, written)
        if attach:
            raw.dims[0].attach_scale(sample)
            volts.dims[0].attach_scale(time)


def _axis(group, base: str, n: int, p: Preamble | None, written: dict):
    """The axis ``base`` (``base_2``, ... for another length or time base) of ``group``:
    seconds from the trigger for a preamble, a sample index for None."""
    k = 1
    while True:
        name = base if k == 1 else f"{base}_{k}"
        values = np.arange(n, dtype=np.int64) if p is None else p.x_zero + p.x_increment * np.arange(n)
        if name not in group:
            axis = _put(group, name, values, written, **_chunks(n))
            if p is not None:
                axis.attrs["units"] = p.x_unit
            axis.make_scale(name)
            return axis
        old = group[name]
        known = written.get(address(old))  # written by this call: compared by digest, not read back
        if old.shape == (n,) and (known == value_digest(values) if known else np.array_equal(old[()], values)):
            return old
        k += 1


def _put(parent, name: str, data, written: dict, **options):
    """The dataset ``parent[name]`` holding ``data``; its digest (digest.value_digest, the
    row a reader computes from the values read back) kept in ``written`` by address."""
    d = parent.create_dataset(name, data=data, **options)
    written[address(d)] = value_digest(data)
    return d


def _group(parent, name: str, nx_class: str):
    g = parent.require_group(name)
    g.attrs["NX_class"] = nx_class
    return g


def _objects(group) -> list:
    out = [group]
    group.visititems(lambda name, obj: out.append(obj))
    return out


def _preamble_json(w: Waveform) -> str:
    return json.dumps({"channel": w.channel, "overrange": bool(w.overrange), **asdict(w.preamble)},
                      default=_jsonable, sort_keys=True)


def _facts_json(e: Entry, where: str) -> str:
    """The facts as stored (JSON with their version; "{}": none), checked as a reader will
    check them: the archive refuses to write facts it would refuse to read."""
    if e.facts is None:
        return "{}"
    if not isinstance(e.facts, ShotFacts):
        raise InstrumentError(f"{where} = {type(e.facts).__name__}: expected ShotFacts (instruments.archive.facts) or None")
    text = json.dumps(e.facts.to_dict(), default=_jsonable)
    ShotFacts.from_dict(json.loads(text), where)
    return text


def _chunks(n: int, shuffle: bool = True) -> dict:
    """Chunking and filters of an array of ``n`` values. ``shuffle`` (byte planes before
    gzip) suits smooth or arithmetic floats (axes, forces); volts computed from 8- or 16-bit
    codes take few distinct values, which gzip alone packs about 3 times smaller, in a third
    of the CPU time (3 x 10,000 points: 26 -> 9 kB a channel)."""
    return dict(chunks=(max(1, min(int(n), 65536)),), **{**COMPRESSION, "shuffle": shuffle}) if n else {}


def _jsonable(x):
    if isinstance(x, np.generic):
        return x.item()
    if isinstance(x, (tuple, set)):
        return list(x)
    return str(x)
