"""Reading one NXentry of the current layout (instruments/archive/layout.py) back into
the Entry it was written from: the same scope records (codes, preamble with its point
format, channel names), facts and truth. The checksums are checked by the caller
(instruments/archive/__init__.py)."""
from __future__ import annotations

import json
from dataclasses import fields
from typing import TYPE_CHECKING

from ..errors import InstrumentError
from ..records import Preamble, ScopeRecord, Waveform
from .digest import linked_groups
from .facts import ShotFacts
from .layout import Entry

if TYPE_CHECKING:
    import h5py


def read_entry(g: h5py.Group, path, with_truth: bool = True, keyed: bool = False) -> Entry:
    """The Entry of an NXentry of layout 2 (its checksums are checked by the caller); with
    ``keyed``, its truth_key that of the scene's shared group it links to (``rig upgrade``
    keeps the shots of one scene sharing one group)."""
    shot_id = int(g.name.rsplit("_", 1)[1])
    where = f"{path}: shot {shot_id}"
    waves = {}
    for name, d in g["instrument/oscilloscope"].items():
        if "preamble" not in d.attrs:
            continue  # the sample axis
        meta = json.loads(d.attrs["preamble"])
        ch, overrange = meta.pop("channel"), meta.pop("overrange")
        unknown = set(meta) - {f.name for f in fields(Preamble)}
        if unknown:
            raise InstrumentError(f"{where}: channel {ch}: preamble.{sorted(unknown)[0]}: unknown key")
        pre = Preamble(**meta)
        values = d[()]
        kind = "samples" if values.dtype.kind == "f" else "codes"  # volts from a file that held volts only
        waves[ch] = Waveform(ch, pre, overrange=overrange, **{kind: values})
    reason = _text(g, "no_trigger_reason")
    record = ScopeRecord(dict(sorted(waves.items())), bool(g["triggered"][()]), reason or None)
    truth, facts = None, None
    if "truth" in g:
        stored = json.loads(_text(g["truth"], "facts"))
        facts = ShotFacts.from_dict(stored, f"{where}: facts") if stored else None
        if with_truth:
            forces = g["truth/forces"]
            axis = forces.attrs["axes"][0]
            truth = {k: v[()] for k, v in forces.items() if k != axis}
    keys = sorted(k for k in linked_groups(g, "/shared/") if k.startswith("scene_")) if keyed else []
    return Entry(record, bool(g["simulated"][()]), int(g["seed"][()]) if "seed" in g else None,
                 _text(g, "scene"), _text(g, "scene_text"), json.loads(_text(g, "settings")), truth, facts,
                 keys[0].removeprefix("scene_") if keys else None,
                 _text(g, "start_time"), g["program_name"].attrs["version"], shot_id,
                 g["start_time"].attrs["source"], _text(g, "file_modification_time"), _text(g, "title"))


def _text(g, name: str) -> str:
    if name not in g:
        return ""
    value = g[name][()]
    return value.decode() if isinstance(value, bytes) else str(value)
