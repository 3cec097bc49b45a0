"""Reading one NXentry of layout 2 or 3 (instruments/archive/layout.py) or of layout 4
(instruments/archive/compact.py) back into the Entry it was written from: the same scope
records (codes, preamble with its point format, channel names), facts and truth; and
checked against its table of checksums and its raw data's SHA-256 (checked_shot), the shared
groups it links to checked by the caller (instruments/archive/shared.py)."""
from __future__ import annotations

import contextlib
import json
from dataclasses import fields
from typing import TYPE_CHECKING

from ..errors import InstrumentError
from ..records import Preamble, ScopeRecord, Waveform
from .compact import LAYOUT4
from .compare import damage
from .entry import Entry, raw_digest
from .facts import ShotFacts
from .hashes import attribute_digest, value_digest
from .links import returned_by_read
from .opening import stored_raw_digest
from .shared import Shared, truth_forces
from .stored import linked_groups
from .values import attribute_value, dataset_value, member_value

if TYPE_CHECKING:
    import h5py


def checked_shot(g: h5py.Group, path, where: str, layout, shared: Shared, with_truth: bool = True) -> Entry:
    """The Entry of the shot ``g`` (read_shot; ``layout``: of the file that holds it),
    checked with ``shared`` (what it links to, checked: shared.SharedGroups.check): the rows
    of its table that a read returns (links.returned_by_read), those of what it read computed
    from the values read, not read again, and its raw data's SHA-256; InstrumentError
    (``where`` first) naming the first damage."""
    e: Entry | None = None
    seen: dict = {}  # the rows of what read_shot read, not read again by the check
    with contextlib.suppress(Exception):  # a damaged shot: the check says what
        e = read_shot(g, path, with_truth, seen=seen, layout=layout, scene=shared.scene, truth=shared.truth)
    problems = damage(g, shared.linked, read=returned_by_read(layout), known=seen if e is not None else {},
                      text=shared.table)
    if problems:
        raise InstrumentError(f"{where}: {problems[0]}")
    e = e or read_shot(g, path, with_truth, layout=layout)
    if raw_digest(e.record) != (e.raw_sha256 or stored_raw_digest(g)):
        raise InstrumentError(f"{where}: raw_sha256 does not match the raw data")
    return e


def read_shot(g: h5py.Group, path, with_truth: bool = True, keyed: bool = False, seen: dict | None = None,
              layout=None, scene: dict | None = None, truth: dict | None = None) -> Entry:
    """The Entry of an NXentry of any current layout (the file that holds it says which, or
    ``layout`` where the caller has read it); ``seen`` and ``scene`` (layout 4): as for
    read_compact_entry; ``truth``: as for read_entry."""
    if (g.file.attrs.get("layout_version") if layout is None else layout) == LAYOUT4:
        return read_compact_entry(g, path, with_truth, keyed, {} if seen is None else seen, scene, truth)
    return read_entry(g, path, with_truth, keyed, truth)


def read_compact_entry(g: h5py.Group, path, with_truth: bool = True, keyed: bool = False,
                       seen: dict | None = None, scene: dict | None = None, truth: dict | None = None) -> Entry:
    """The Entry of an NXentry of layout 4 (its checksums are checked by the caller);
    ``keyed`` as for read_entry; ``seen``: filled with {row key: row} (digest.table) of the
    metadata, texts and codes read, which the caller's check takes rather than read again;
    ``scene``: the texts of the shared group its scene_text and settings link to
    ({"scene_text", "settings"}, as stored), where the caller has read them from it: not read
    again through the shot's links; ``truth``: as for read_entry."""
    shot_id = int(g.name.rsplit("_", 1)[1])
    where = f"{path}: shot {shot_id}"
    seen = {} if seen is None else seen
    text = attribute_value(g, "metadata")
    seen["@metadata"] = attribute_digest(text)
    meta = json.loads(text)
    data = g["data"]
    waves = dict(_waveform(_codes(data, ch.replace("#", "_"), seen), p, where) for ch, p in meta["preambles"].items())
    order = meta.get("channel_order") or sorted(waves)  # shots stored before the order was kept: by name
    record = ScopeRecord({ch: waves[ch] for ch in order}, bool(meta["triggered"]), meta["no_trigger_reason"] or None)
    facts = ShotFacts.from_dict(meta["facts"], f"{where}: facts") if meta.get("facts") else None
    truth = (truth or truth_forces(g["truth/forces"])) if with_truth and "truth" in g else None
    keys = sorted(k for k in linked_groups(g, "/shared/") if k.startswith("scene_")) if keyed else []
    texts = meta if "scene_text" in meta else scene or {k: _text(g, k) for k in ("scene_text", "settings")}
    scene_text = texts["scene_text"]
    settings = meta["settings"] if "settings" in meta else json.loads(texts["settings"])
    return Entry(record, bool(meta["simulated"]), meta["seed"], meta["scene"], scene_text,
                 settings, truth, facts, keys[0].removeprefix("scene_") if keys else None,
                 _text(g, "start_time", seen), meta["program_version"], shot_id, meta["start_time_source"],
                 meta["file_modification_time"], _text(g, "title", seen), meta.get("raw_sha256", ""))


def read_entry(g: h5py.Group, path, with_truth: bool = True, keyed: bool = False, truth: dict | None = None) -> Entry:
    """The Entry of an NXentry of layout 2 (its checksums are checked by the caller); with
    ``keyed``, its truth_key that of the scene's shared group it links to (``rig upgrade``
    keeps the shots of one scene sharing one group); ``truth``: the forces of the shared
    group its truth links to, where the caller has them (truth_forces): not read again."""
    shot_id = int(g.name.rsplit("_", 1)[1])
    where = f"{path}: shot {shot_id}"
    waves = {}
    for d in g["instrument/oscilloscope"].values():
        if "preamble" in d.attrs:  # not the sample axis
            ch, wave = _waveform(dataset_value(d.id), json.loads(d.attrs["preamble"]), where)
            waves[ch] = wave
    reason = _text(g, "no_trigger_reason")
    record = ScopeRecord(dict(sorted(waves.items())), bool(g["triggered"][()]), reason or None)
    facts = None
    if "truth" in g:
        stored = json.loads(_text(g["truth"], "facts"))
        facts = ShotFacts.from_dict(stored, f"{where}: facts") if stored else None
    truth = (truth or truth_forces(g["truth/forces"])) if with_truth and "truth" in g else None
    keys = sorted(k for k in linked_groups(g, "/shared/") if k.startswith("scene_")) if keyed else []
    return Entry(record, bool(g["simulated"][()]), int(g["seed"][()]) if "seed" in g else None,
                 _text(g, "scene"), _text(g, "scene_text"), json.loads(_text(g, "settings")), truth, facts,
                 keys[0].removeprefix("scene_") if keys else None,
                 _text(g, "start_time"), g["program_name"].attrs["version"], shot_id,
                 g["start_time"].attrs["source"], _text(g, "file_modification_time"), _text(g, "title"))


def summary_row(e: Entry) -> dict:
    """A shot's row of ``rig list``: id, title, start time (and what it is), simulated,
    scene, seed, triggered, channels, source files, the striker's settings."""
    return {"shot": e.shot_id, "title": e.title, "start_time": e.start_time, "start_time_source": e.start_time_source,
            "simulated": e.simulated, "scene": e.scene, "seed": e.seed, "triggered": e.record.triggered,
            "channels": list(e.record.waveforms), "sources": e.settings.get("source_files", []),
            "settings": e.settings.get("striker", {})}


def _codes(data, name: str, seen: dict):
    """The raw codes (or volts) of the channel ``name`` in a layout-4 shot's ``data``; their
    row of the shot's table kept in ``seen``."""
    values = member_value(data, name)
    seen[f"data/{name}"] = value_digest(values)
    return values


def _waveform(values, preamble: dict, where: str) -> tuple:
    """(channel, Waveform) of a channel's raw codes (or volts) and its preamble (with the
    channel's name and over-range flag)."""
    meta = dict(preamble)
    ch, overrange = meta.pop("channel"), meta.pop("overrange")
    unknown = set(meta) - {f.name for f in fields(Preamble)}
    if unknown:
        raise InstrumentError(f"{where}: channel {ch}: preamble.{sorted(unknown)[0]}: unknown key")
    kind = "samples" if values.dtype.kind == "f" else "codes"  # volts from a file that held volts only
    return ch, Waveform(ch, Preamble(**meta), overrange=overrange, **{kind: values})


def _str(value) -> str:
    if value is None:
        return ""
    return value.decode() if isinstance(value, bytes) else str(value)


def _text(g, name: str, seen: dict | None = None) -> str:
    if name not in g:
        return ""
    value = member_value(g, name)
    if seen is not None:
        seen[name] = value_digest(value)
    return _str(value)
