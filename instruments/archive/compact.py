"""Layout 4: one shot in a handful of HDF5 objects. The part files of layout 3's transaction
model (instruments/archive/parts.py) hold shots of this form; the master is layout 3's.

h5py's cost is per object (a dataset, a group, an attribute: its header, its B-tree, its
write and read back), not per byte, so a shot is few objects: the raw codes once, in the
NXdata plot itself, read as volts through CF packing attributes (``scale_factor`` = YMULT,
``add_offset`` = YZERO - YOFF*YMULT: xarray and h5netcdf decode them by default); the time
axis as a sample index (uint16, or uint32 past 65,536 points) packed the same way (seconds =
x_zero + x_increment*n); the shot's scalars, preambles and facts as one JSON attribute of its
NXentry (``metadata``); one table of checksums, whose rows the writer makes from what it
writes, as it writes it: the shot is neither walked nor read back. Its datasets, groups and
attributes are made through HDF5's own calls where h5py's cost more (layout.store). Codes
are chunked with fletcher32 and not compressed (3 x 10,000 int16 codes are 60 kB; gzip
would cost more CPU than the bytes it saves); the index axis is gzipped (a few hundred
bytes).
"""
from __future__ import annotations

import functools
import json
from datetime import datetime, timezone

import numpy as np

from ..errors import InstrumentError
from ..records import ScopeRecord
from .addresses import external_row
from .digest import attribute_digest, member_row, seal_rows
from .entry import NAME, Entry, facts_json, jsonable, preamble_fields, raw_digest, raw_values
from .layout import new_group, scene_group, store

LAYOUT4 = 4
LAYOUT4_TEXT = """Layout version 4 (NeXus). One NXentry per shot (shot_NNNNNN) with the fields title
and start_time (ISO 8601) and the attribute metadata (JSON): scene, seed (virtual shots; null
for a real one), simulated, triggered, no_trigger_reason, program_name, program_version,
raw_sha256 (of the raw codes and their scaling), start_time_source (what start_time is),
file_modification_time (imported files without an acquisition time), facts (virtual shots),
preambles ({channel: its Tektronix scaling and over-range flag}). scene_text (TOML as fired)
and settings (JSON, SI) are links to the scene's shared group where shots share one (virtual
shots: their truth's key); a shot alone (an imported file) holds them in metadata instead. data/ (NXdata, the default
plot): CHn, the raw ADC codes as the scope sent them (volts, float64, where a file held
volts only), with CF packing attributes: volts = scale_factor * codes + add_offset
(= y_zero + y_multiplier * (codes - y_offset)), units 'V' (of the volts); time, the sample
index n with scale_factor = x_increment and add_offset = x_zero: seconds from the trigger
(time_2, ... for another length or time base). The first channel is the signal, the others
its auxiliary_signals. truth/ (virtual shots): forces/ (NXdata, a link into the scene's
shared group): the noise-free forces (N) against their own time (s), stored once per scene
under shared/. Every array is chunked with fletcher32; each entry's and each shared group's
'checksums' table holds the SHA-256 of every dataset and attribute, and its attribute 'sha256' that of the table."""
CODES = {"fletcher32": True}  # chunked (fletcher32 needs chunks), not compressed
INDEX = {"compression": "gzip", "compression_opts": 1, "shuffle": True, "fletcher32": True}


def write_compact_entry(f, shot_id: int, e: Entry, checked: dict, stored: dict, axes: dict) -> str:
    """Write one NXentry of layout 4 into a part file, then seal its table of checksums (an
    attribute); ``checked`` and ``stored`` as for instruments.archive.layout.write_entry;
    ``axes``: the time axes this transaction wrote ({(time base, name): (dataset, its rows)}),
    which a later shot of the same time base hard-links to rather than writing its own. The
    table's rows are those the writer gives each item as it writes it (digest.table's rows,
    from the values written): the shot is not walked nor read back. Returns the table's
    text as written (the part's digest is made of it: part_digests.part_tables)."""
    written: dict = {}  # digests of a scene's shared group this call writes, by address (digest.table)
    rows: dict = {}  # the shot's table, by path (digest.table)
    where = f"shot {shot_id}"
    meta = {"scene": e.scene, "seed": e.seed, "simulated": bool(e.simulated), "triggered": bool(e.record.triggered),
            "no_trigger_reason": e.record.reason or "", "program_name": "sonic-rig",
            "program_version": e.project_version, "raw_sha256": raw_digest(e.record),
            "start_time_source": e.start_time_source or "when the shot was archived",
            "file_modification_time": e.file_modification_time,
            "facts": json.loads(facts_json(e, f"{where}: facts")) if e.truth is not None else None,
            "preambles": {ch: preamble_fields(w) for ch, w in sorted(e.record.waveforms.items())},
            "channel_order": list(e.record.waveforms)}  # the record's own order (the JSON sorts its keys)
    shares = e.truth_key is not None or e.truth is not None  # a scene's shots share its group
    if shares:
        members = scene_group(f, shot_id, e, checked, stored, written)[0]
    else:  # a shot alone (an imported file): its texts in its metadata, no group of its own under shared/
        meta.update(scene_text=e.scene_text, settings=e.settings)
    g = new_group(f, f"shot_{shot_id:06d}")
    text = json.dumps(meta, sort_keys=True, default=jsonable)
    label(g, {"NX_class": "NXentry", "default": "data", "metadata": text}, rows, "")
    title = e.title or (f"{e.scene} seed {e.seed}" if e.simulated else ", ".join(e.settings.get("source_files", [])))
    store(g, "title", title or f"shot {shot_id}", rows, key="title")
    store(g, "start_time", e.start_time or datetime.now(timezone.utc).isoformat(), rows, key="start_time")
    names = ["title", "start_time", "data"]
    if shares:
        for name in ("scene_text", "settings"):
            rows[name] = link(g, name, members[name])
        names += ["scene_text", "settings"]
    _write_channels(g, e.record, rows, axes)
    if e.truth is not None:
        label(new_group(g, "truth"), {"NX_class": "NXcollection"}, rows, "truth")
        rows["truth/forces"] = link(g, "truth/forces", members["forces"])  # the arrays stored once per scene
        rows["truth/"] = member_row(["forces"])
        names.append("truth")
    rows["/"] = member_row(names)
    return seal_rows(g, rows, attribute=True)


def link(g, name: str, target) -> str:
    """``g[name]`` made a link to ``target`` (an object of this file: a hard link; an
    h5py.ExternalLink: itself); its row of the table (digest.table: the link, not followed)."""
    g[name] = target
    return "link:" + target.name if hasattr(target, "id") else external_row(target)


def _write_channels(g, record: ScopeRecord, rows: dict, axes: dict):
    """data/: each channel's raw codes (CF-packed volts) and one time axis per time base."""
    chans = list(record.waveforms)  # the record's order: the NXdata signal is its first channel
    names = [ch.replace("#", "_") for ch in chans]  # "CH1#2", the second record of CH1 in a file: CH1_2
    for ch, name in zip(chans, names):
        if not NAME.match(name):
            raise InstrumentError(f"channel {ch!r}: allowed letters, digits, '_' and '#'")
    data = new_group(g, "data")
    plot = {"NX_class": "NXdata", "signal": names[0] if names else "", "axes": ["time"]}
    if len(names) > 1:  # NeXus: the other channels, plotted with the signal by viewers (silx, nexpy)
        plot["auxiliary_signals"] = names[1:]
    label(data, plot, rows, "data")
    named: dict = {}  # {(points, x_zero, x_increment, x_unit): the axis's name in this shot}
    for ch, name in zip(chans, names):
        w = record.waveforms[ch]
        p = w.preamble
        values = raw_values(w)
        path = f"data/{name}"
        d = store(data, name, values, rows, key=path, chunks=_chunk(values.size), **CODES) if values.size else \
            store(data, name, values, rows, key=path)
        attrs = {"units": p.y_unit}
        if w.codes is not None:
            attrs.update(scale_factor=np.float64(p.y_multiplier),
                         add_offset=np.float64(p.y_zero - p.y_offset * p.y_multiplier))
        label(d, attrs, rows, path)
        base = (p.points, p.x_zero, p.x_increment, p.x_unit)
        if base not in named:
            named[base] = "time" if not named else f"time_{len(named) + 1}"
            key = (base, named[base])
            if key in axes:  # a hard link to the axis an earlier shot of this part wrote
                data[named[base]] = axes[key][0]
            else:
                axes[key] = _write_axis(data, named[base], p)
            rows.update({f"data/{named[base]}{k}": row for k, row in axes[key][1].items()})
    rows["data/"] = member_row(names + list(named.values()))


def _write_axis(data, name: str, p) -> tuple:
    """The time axis ``name``: the sample index, CF-packed to seconds from the trigger;
    (the dataset, its rows of a shot's table, by what follows its path: "" its values,
    "@units" ...)."""
    n = int(p.points)
    index = np.arange(n, dtype=np.uint16 if n <= 65536 else np.uint32)
    rows: dict = {}
    axis = store(data, name, index, rows, key="", chunks=_chunk(n), **INDEX) if n else \
        store(data, name, index, rows, key="")
    label(axis, {"units": p.x_unit, "scale_factor": np.float64(p.x_increment), "add_offset": np.float64(p.x_zero)},
          rows, "")
    axis.make_scale(name)
    rows.update({f"@{k}": attribute_digest(axis.attrs[k]) for k in axis.attrs if f"@{k}" not in rows})  # HDF5's own
    return axis, rows


def label(obj, attrs: dict, rows: dict, path: str):
    """Give ``obj`` (at ``path`` in the shot) the attributes ``attrs`` (texts, lists of texts,
    numpy scalars), written through HDF5's own calls (h5py's attrs[...] costs twice as much),
    as h5py writes them; their rows of the table (``path@name``: digest.attribute_digest)
    kept in ``rows``: not read back."""
    import h5py

    for key, value in attrs.items():
        texts = isinstance(value, (str, list))
        data = np.array(value, dtype=h5py.string_dtype()) if texts else np.asarray(value)
        kind, scalar = _attribute_kind("text" if texts else data.dtype.str)
        space = h5py.h5s.create_simple(data.shape) if data.shape else scalar
        h5py.h5a.create(obj.id, key.encode(), kind, space).write(data)
        rows[f"{path}@{key}"] = attribute_digest(value)


@functools.cache
def _attribute_kind(dtype: str) -> tuple:
    """(the HDF5 type h5py gives an attribute of ``dtype``: "text" or a numpy type's code,
    HDF5's scalar dataspace), made once in a process."""
    import h5py

    kind = h5py.h5t.py_create(h5py.string_dtype() if dtype == "text" else np.dtype(dtype), logical=True)
    return kind, h5py.h5s.create(h5py.h5s.SCALAR)


def _chunk(n: int) -> tuple:
    return (max(1, min(int(n), 65536)),)
