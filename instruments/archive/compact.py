"""Layout 4: one shot in a handful of HDF5 objects. The part files of layout 3's transaction
model (instruments/archive/parts.py) hold shots of this form; the master is layout 3's.

h5py's cost is per object (a dataset, a group, an attribute: its header, its B-tree, its
write and read back), not per byte, so a shot is few objects: the raw codes once, in the
NXdata plot itself, read as volts through CF packing attributes (``scale_factor`` = YMULT,
``add_offset`` = YZERO - YOFF*YMULT: xarray and h5netcdf decode them by default); the time
axis as a sample index (uint16, or uint32 past 65,536 points) packed the same way (seconds =
x_zero + x_increment*n); the shot's scalars as attributes of its NXentry; one table of
checksums. Codes are chunked with fletcher32 and not compressed (3 x 10,000 int16 codes are
60 kB; gzip would cost more CPU than the bytes it saves); the index axis is gzipped (a few
hundred bytes).
"""
from __future__ import annotations

from datetime import datetime, timezone

import numpy as np

from ..errors import InstrumentError
from ..records import ScopeRecord
from .digest import seal
from .entry import NAME, Entry, facts_json, preamble_json, raw_digest, raw_values
from .layout import nx_group, scene_group, store

LAYOUT4 = 4
LAYOUT4_TEXT = """Layout version 4 (NeXus). One NXentry per shot (shot_NNNNNN) with the fields title
and start_time (ISO 8601; its attribute 'source' says what the time is) and the attributes
scene, seed (virtual shots), simulated, triggered, no_trigger_reason, file_modification_time
(imported files without an acquisition time), program_name, program_version, raw_sha256 (of
the raw codes and their scaling). scene_text (TOML as fired) and settings (JSON, SI) are links
to the scene's shared group. data/ (NXdata, the default plot): CHn, the raw ADC codes as the
scope sent them (volts, float64, where a file held volts only), with CF packing attributes:
volts = scale_factor * codes + add_offset (= y_zero + y_multiplier * (codes - y_offset)),
units 'V' (of the volts), and 'preamble', the channel's Tektronix scaling (JSON); time, the
sample index n with scale_factor = x_increment and add_offset = x_zero: seconds from the
trigger (time_2, ... for another length or time base). The first channel is the signal,
the others its auxiliary_signals. truth/ (virtual shots, NXcollection): the attribute facts
(JSON) and forces/ (NXdata, a link into the scene's shared group): the noise-free forces
(N) against their own time (s), stored once per scene under shared/. Every array is chunked
with fletcher32; each entry's and each shared group's 'checksums' table holds the SHA-256 of
every dataset and attribute, and its attribute 'sha256' that of the table."""
CODES = {"fletcher32": True}  # chunked (fletcher32 needs chunks), not compressed
INDEX = {"compression": "gzip", "compression_opts": 1, "shuffle": True, "fletcher32": True}


def write_compact_entry(f, shot_id: int, e: Entry, checked: set, stored: dict):
    """Write one NXentry of layout 4 into a part file, then seal its table of checksums;
    ``checked`` and ``stored`` as for instruments.archive.layout.write_entry."""
    written = {}  # {address: value_digest} of the datasets this call writes (digest.table)
    where = f"shot {shot_id}"
    facts = facts_json(e, f"{where}: facts") if e.truth is not None else None
    members, linked = scene_group(f, shot_id, e, checked, stored, written)
    g = f.create_group(f"shot_{shot_id:06d}")
    title = e.title or (f"{e.scene} seed {e.seed}" if e.simulated else ", ".join(e.settings.get("source_files", [])))
    attrs = {"NX_class": "NXentry", "default": "data", "scene": e.scene, "simulated": np.uint8(e.simulated),
             "triggered": np.uint8(e.record.triggered), "program_name": "sonic-rig",
             "program_version": e.project_version, "raw_sha256": raw_digest(e.record)}
    optional = {"seed": None if e.seed is None else np.int64(e.seed), "no_trigger_reason": e.record.reason,
                "file_modification_time": e.file_modification_time}
    g.attrs.update({**attrs, **{k: v for k, v in optional.items() if v is not None and v != ""}})
    store(g, "title", title or f"shot {shot_id}", written)
    start = store(g, "start_time", e.start_time or datetime.now(timezone.utc).isoformat(), written)
    start.attrs["source"] = e.start_time_source or "when the shot was archived"
    g["scene_text"] = members["scene_text"]
    g["settings"] = members["settings"]
    _write_channels(g, e.record, written)
    if e.truth is not None:
        tg = nx_group(g, "truth", "NXcollection")
        tg.attrs["facts"] = facts
        tg["forces"] = members["forces"]  # one link to the arrays stored once per scene
    seal(g, linked, written)


def _write_channels(g, record: ScopeRecord, written: dict):
    """data/: each channel's raw codes (CF-packed volts) and one time axis per time base."""
    chans = sorted(record.waveforms)
    names = [ch.replace("#", "_") for ch in chans]  # "CH1#2", the second record of CH1 in a file: CH1_2
    for ch, name in zip(chans, names):
        if not NAME.match(name):
            raise InstrumentError(f"channel {ch!r}: allowed letters, digits, '_' and '#'")
    data = nx_group(g, "data", "NXdata")
    data.attrs.update({"signal": names[0] if names else "", "axes": ["time"]})
    if len(names) > 1:  # NeXus: the other channels, plotted with the signal by viewers (silx, nexpy)
        data.attrs["auxiliary_signals"] = names[1:]
    axes = {}  # {(points, x_zero, x_increment, x_unit): the axis's name}
    for ch, name in zip(chans, names):
        w = record.waveforms[ch]
        p = w.preamble
        values = raw_values(w)
        d = store(data, name, values, written, chunks=_chunk(values.size), **CODES) if values.size else \
            store(data, name, values, written)
        attrs = {"units": p.y_unit, "preamble": preamble_json(w)}
        if w.codes is not None:
            attrs.update(scale_factor=np.float64(p.y_multiplier),
                         add_offset=np.float64(p.y_zero - p.y_offset * p.y_multiplier))
        d.attrs.update(attrs)
        base = (p.points, p.x_zero, p.x_increment, p.x_unit)
        if base not in axes:
            axes[base] = "time" if not axes else f"time_{len(axes) + 1}"
            _write_axis(data, axes[base], p, written)


def _write_axis(data, name: str, p, written: dict):
    """The time axis ``name``: the sample index, CF-packed to seconds from the trigger."""
    n = int(p.points)
    index = np.arange(n, dtype=np.uint16 if n <= 65536 else np.uint32)
    axis = store(data, name, index, written, chunks=_chunk(n), **INDEX) if n else store(data, name, index, written)
    axis.attrs.update({"units": p.x_unit, "scale_factor": np.float64(p.x_increment),
                       "add_offset": np.float64(p.x_zero)})
    axis.make_scale(name)


def _chunk(n: int) -> tuple:
    return (max(1, min(int(n), 65536)),)
