"""How one shot lies in an archive of layout 2 (one file) and in the part files of layout 3:
the writer of one NXentry, and of a scene's shared group (scene text, settings, the truth's
forces), which layout 4 (instruments/archive/compact.py) writes alike.

The layout (version 2; ``LAYOUT`` below, also stored in the file) is NeXus: valid names,
NX_class on every group, ``title`` and ``start_time`` on every entry, signal/axes/units on
every NXdata, volts and seconds as floats in ``data/``. Every array dataset is chunked with
the fletcher32 checksum; every group's tree (values and attributes) is in its table of
SHA-256 checksums (instruments/archive/digest.py).
"""
from __future__ import annotations

import functools
from datetime import datetime, timezone
from typing import TYPE_CHECKING

import numpy as np

from ..errors import InstrumentError
from ..records import Preamble, ScopeRecord
from .addresses import address
from .digest import seal, value_digest
from .entry import NAME, Entry, facts_json, preamble_json, raw_digest, raw_values, shared_name, texts

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


def write_entry(f: h5py.File, shot_id: int, e: Entry, checked: dict, stored: dict | None = None):
    """Write one NXentry, then seal its table of checksums; ``checked`` holds the shared
    groups already compared this transaction ({} at its start; scene_group). ``stored``
    (layout 3, a part file; {key: (part file, group)}) names the shared groups an earlier
    transaction wrote into another part,
    which the entry links to with HDF5 external links; in a part, the axes are dimension
    scales attached to nothing (h5netcdf reads an attached scale's reference in the file it
    opened, the master, where it does not lie; it gives an unattached variable the
    dimension of its length in its group: ``time``)."""
    attach = stored is None
    written: dict = {}  # {address: value_digest} of the datasets this call writes (digest.table)
    def put(parent, name, data, **kw):
        return store(parent, name, data, written, **kw)
    where = f"shot {shot_id}"
    facts = facts_json(e, f"{where}: facts") if e.truth is not None else None
    members, linked = scene_group(f, shot_id, e, checked, stored, written)
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
        tg = nx_group(g, "truth", "NXcollection")
        put(tg, "facts", facts)
        tg["forces"] = members["forces"]  # one link to the arrays stored once per scene
    seal(g, linked, written)


def scene_group(f, shot_id: int, e: Entry, checked: dict, stored: dict | None, written: dict) -> tuple:
    """(the objects a shot links to: {"scene_text", "settings", "forces"}, {address: path}
    of those that lie in this file): its scene's shared group, written where this file does
    not hold it yet and no earlier part does (``stored``, as for write_entry), else compared
    with the shot's texts (once per transaction: ``checked``, {key: {with truth: what this
    returned}})."""
    key, where, truth = shared_name(e, shot_id), f"shot {shot_id}", e.truth is not None
    known = checked.get(key, {}).get(truth)
    if known:  # a shot of a scene this transaction met already: its group's objects, not walked again
        return known
    if stored and key in stored:
        out = _stored(key, e, where, checked, *stored[key])
    else:
        shared = _shared(f, key, e, where, checked, stored is None, written)
        out = shared, {address(o): o.name for o in _objects(shared)}
    checked[key][truth] = out
    return out


def _compare(s, key: str, e: Entry, where: str):
    for name, text in texts(e).items():
        if s[name][()].decode() != text:
            raise InstrumentError(f"{where}: shared/{key}/{name} differs from this shot's {name}")


def _stored(key: str, e: Entry, where: str, checked: dict, part: str, s) -> tuple:
    """External links to shared/<key> in the part file ``part`` (``s``: that group, read),
    and no linked objects (an external link is its own row in the table)."""
    import h5py

    if key not in checked:
        _compare(s, key, e, where)
        if e.truth is not None and "forces" not in s:
            raise InstrumentError(f"{where}: shared/{key} was stored without truth forces; this shot has them "
                                  "(give it another truth_key)")
        checked.setdefault(key, {})
    names = ["scene_text", "settings"] + (["forces"] if e.truth is not None else [])
    return {n: h5py.ExternalLink(part, f"/shared/{key}/{n}") for n in names}, {}


def _shared(f, key: str, e: Entry, where: str, checked: dict, attach: bool, written: dict):
    """shared/<key>: scene text, settings and truth forces, stored once per scene."""
    root = nx_group(f, "shared", "NXcollection")
    scene_texts = texts(e)
    if key in root and key not in checked:
        _compare(root[key], key, e, where)
    s = nx_group(root, key, "NXcollection")
    fresh = "checksums" not in s
    for name, text in scene_texts.items():
        if name not in s:
            store(s, name, text, written)
    if e.truth is not None and "forces" not in s:
        _write_forces(s, e, where, attach, written)
        fresh = True
    if fresh:
        if "checksums" in s:
            del s["checksums"]
        seal(s, {}, written)
    checked.setdefault(key, {})
    return s


def _write_forces(s, e: Entry, where: str, attach: bool, written: dict):
    assert e.truth is not None, "written for a shot with a truth"
    names = list(e.truth)
    bad = [n for n in names if not NAME.match(n) or n in ("time", "sample")]
    if bad:
        raise InstrumentError(f"{where}: truth name {bad[0]!r}: allowed letters, digits and '_', "
                              "not starting with a digit, not 'time' or 'sample'")
    forces = nx_group(s, "forces", "NXdata")
    n = len(np.asarray(e.truth[names[0]])) if names else 0
    if e.facts is not None:
        axis = store(forces, "time", np.arange(n) * e.facts.sample_interval_s, written, **_chunks(n))
        axis.attrs["units"] = "s"
    else:  # no facts: no sample interval, an index
        axis = store(forces, "sample", np.arange(n, dtype=np.int64), written, **_chunks(n))
    axis.make_scale(axis.name.rsplit("/", 1)[1])
    forces.attrs.update({"signal": names[0] if names else "", "axes": [axis.name.rsplit("/", 1)[1]]})
    if len(names) > 1:
        forces.attrs["auxiliary_signals"] = names[1:]
    for name in names:
        d = store(forces, name, np.asarray(e.truth[name], dtype=np.float64), written, **_chunks(n))
        d.attrs["units"] = "N"
        if attach:
            d.dims[0].attach_scale(axis)


def _write_record(g, record: ScopeRecord, attach: bool, written: dict):
    scope = nx_group(nx_group(g, "instrument", "NXinstrument"), "oscilloscope", "NXcollection")
    data = nx_group(g, "data", "NXdata")
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
        raw = store(scope, name, values, written, **_chunks(values.size))
        raw.attrs.update({"units": "counts" if w.codes is not None else p.y_unit, "preamble": preamble_json(w)})
        sample = _axis(scope, "sample", p.points, None, written)
        volts = store(data, name, np.asarray(w.volts(), dtype=np.float64), written, **_chunks(values.size, False))
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
            axis = store(group, name, values, written, **_chunks(n))
            if p is not None:
                axis.attrs["units"] = p.x_unit
            axis.make_scale(name)
            return axis
        old = group[name]
        known = written.get(address(old))  # written by this call: compared by digest, not read back
        if old.shape == (n,) and (known == value_digest(values) if known else np.array_equal(old[()], values)):
            return old
        k += 1


def store(parent, name: str, data, written: dict, key=None, **options):
    """The dataset ``parent[name]`` holding ``data``; its digest (digest.value_digest, the
    row a reader computes from the values read back) kept in ``written`` by address, or by
    ``key`` where given (a writer that knows the dataset's path: instruments/archive/compact.py).
    A text or a numeric array of a kind (type, shape, options) written before in this process
    is made through HDF5's own calls with the type and creation properties h5py gave the
    first (h5py's create_dataset costs three times as much for a text, 1.5 for codes)."""
    import h5py

    text = isinstance(data, str)
    values = np.array(data, dtype=h5py.string_dtype()) if text else data
    kind = ("text" if text else values.dtype.str, values.shape, tuple(sorted(options.items()))) \
        if (text or isinstance(data, np.ndarray) and data.dtype.kind in "biuf" and data.size) and "/" not in name \
        else None
    if kind in _MADE:
        dtype, dcpl = _MADE[kind]
        space = h5py.h5s.create_simple(values.shape) if values.shape else h5py.h5s.create(h5py.h5s.SCALAR)
        made = h5py.h5d.create(parent.id, name.encode(), dtype, space, dcpl=dcpl, lcpl=_utf8_names())
        made.write(h5py.h5s.ALL, h5py.h5s.ALL, np.ascontiguousarray(values))
        d = h5py.Dataset(made)
    else:
        d = parent.create_dataset(name, data=data, **options)
        if kind is not None:
            _MADE[kind] = (d.id.get_type(), d.id.get_create_plist())
    written[address(d) if key is None else key] = value_digest(data)
    return d


_MADE: dict = {}  # {(type, shape, options): (HDF5 type, creation properties)} of the datasets store() made


@functools.cache
def _utf8_names():
    """The link-creation properties h5py gives a new object: its name in UTF-8."""
    import h5py

    lcpl = h5py.h5p.create(h5py.h5p.LINK_CREATE)
    lcpl.set_char_encoding(h5py.h5t.CSET_UTF8)
    return lcpl


def new_group(parent, name: str):
    """The new group ``parent[name]``, made through HDF5's own call with h5py's properties
    (h5py's create_group costs twice as much)."""
    import h5py

    return h5py.Group(h5py.h5g.create(parent.id, name.encode(), lcpl=_utf8_names()))


def nx_group(parent, name: str, nx_class: str):
    """The group ``parent[name]`` (made where missing) of NeXus class ``nx_class``."""
    g = parent.require_group(name)
    g.attrs["NX_class"] = nx_class
    return g


def _objects(group) -> list:
    out = [group]
    group.visititems(lambda name, obj: out.append(obj))
    return out


def _chunks(n: int, shuffle: bool = True) -> dict:
    """Chunking and filters of an array of ``n`` values. ``shuffle`` (byte planes before
    gzip) suits smooth or arithmetic floats (axes, forces); volts computed from 8- or 16-bit
    codes take few distinct values, which gzip alone packs about 3 times smaller, in a third
    of the CPU time (3 x 10,000 points: 26 -> 9 kB a channel)."""
    return dict(chunks=(max(1, min(int(n), 65536)),), **{**COMPRESSION, "shuffle": shuffle}) if n else {}


