"""One shot as every layout of the archive stores it: the Entry a shot is written from and
read back into, the SHA-256 of its raw data, and the texts each layout writes alike (the
shared scene text and settings, a channel's preamble, the facts), as JSON."""
from __future__ import annotations

import hashlib
import json
import re
from dataclasses import dataclass, field, fields

import numpy as np

from ..errors import InstrumentError
from ..records import ScopeRecord, Waveform
from .facts import ShotFacts

NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*\Z")  # a valid NeXus name
PREAMBLE_FLOATS = ("x_increment", "x_zero", "y_multiplier", "y_offset", "y_zero")


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
    raw_sha256: str = ""  # as stored, set when read back from layout 4 (a writer computes its own)


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
        h.update(json.dumps([p.points, p.trigger_index] + [getattr(p, k) for k in PREAMBLE_FLOATS]).encode())
        if p.point_format != "Y":
            h.update(p.point_format.encode())
        h.update(np.ascontiguousarray(raw_values(w)).tobytes())
    return h.hexdigest()


def shared_name(e: Entry, shot_id: int) -> str:
    """The shared group of an entry's scene (a valid NeXus name)."""
    return "scene_" + re.sub(r"\W", "_", e.truth_key) if e.truth_key else f"of_shot_{shot_id:06d}"


def texts(e: Entry) -> dict:
    """The scene text and the settings (JSON, keys sorted) a scene's shared group holds."""
    return {"scene_text": e.scene_text, "settings": json.dumps(e.settings, default=jsonable, sort_keys=True)}


def preamble_json(w: Waveform) -> str:
    """A channel's name, over-range flag and preamble (its scaling: volts and seconds), JSON."""
    return json.dumps(preamble_fields(w), default=jsonable, sort_keys=True)


def preamble_fields(w: Waveform) -> dict:
    """What preamble_json writes, as a dict of the preamble's own values (json.dumps with
    ``default=jsonable`` writes it alike)."""
    p = w.preamble
    return {"channel": w.channel, "overrange": bool(w.overrange), **{f.name: getattr(p, f.name) for f in fields(p)}}


def facts_json(e: Entry, where: str) -> str:
    """The facts as stored (JSON with their version; "{}": none), checked as a reader will
    check them: the archive refuses to write facts it would refuse to read."""
    if e.facts is None:
        return "{}"
    if not isinstance(e.facts, ShotFacts):
        raise InstrumentError(f"{where} = {type(e.facts).__name__}: "
                              "expected ShotFacts (instruments.archive.facts) or None")
    text = json.dumps(e.facts.to_dict(), default=jsonable)
    ShotFacts.from_dict(json.loads(text), where)
    return text


def jsonable(x):
    """What json.dumps writes for a numpy scalar, a tuple or set, and anything else (its str)."""
    if isinstance(x, np.generic):
        return x.item()
    if isinstance(x, (tuple, set)):
        return list(x)
    return str(x)
