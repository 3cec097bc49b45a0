"""The reader of layout 1 (archives written before the layout had a version), kept for
``rig upgrade``, which rewrites such an archive in the current layout.

Layout 1: one NXentry per shot with a compound attribute "shot" (shot_id, seed, simulated,
triggered, scene, start_time, project_version, sha256, no_trigger_reason), scene_text and
settings, instrument/oscilloscope/CHn (raw codes, the group attribute "preamble" a compound
table), truth/ with the attribute "facts" and forces/ (hard-linked from shared/<key>/).
"""
from __future__ import annotations

import json
from typing import TYPE_CHECKING

from ..errors import InstrumentError
from ..records import Preamble, ScopeRecord, Waveform
from .entry import Entry, raw_digest
from .facts import ShotFacts

if TYPE_CHECKING:
    import h5py

_PREAMBLE_FLOATS = ("x_increment", "x_zero", "y_multiplier", "y_offset", "y_zero")


def read_legacy_entry(g: h5py.Group, path) -> Entry:
    """A layout-1 NXentry as an Entry, its SHA-256 of the raw data checked; truth names
    with dots ("upper.average_force") become NeXus names ("upper_average_force")."""
    shot = g.attrs["shot"]
    waves = {}
    scope = g["instrument/oscilloscope"]
    table = scope.attrs["preamble"] if len(scope) else []
    for pa in table:
        ch = pa["channel"].decode()
        extra = json.loads(pa["extra"].decode())
        point_format = "ENV" if extra.pop("point_format", "Y") in ("ENV", "ENVELOPE") else "Y"
        pre = Preamble(points=int(pa["points"]), trigger_index=int(pa["trigger_index"]),
                       byte_count=int(pa["byte_count"]), x_unit=pa["x_unit"].decode(),
                       y_unit=pa["y_unit"].decode(), waveform_id=pa["waveform_id"].decode(),
                       point_format=point_format, extra=extra, **{k: float(pa[k]) for k in _PREAMBLE_FLOATS})
        values = scope[ch][()]
        kind = "samples" if values.dtype.kind == "f" else "codes"
        waves[ch] = Waveform(ch, pre, overrange=bool(pa["overrange"]), **{kind: values})
    record = ScopeRecord(waves, bool(shot["triggered"]), shot["no_trigger_reason"].decode() or None)
    shot_id = int(shot["shot_id"])
    if raw_digest(record) != shot["sha256"].decode():
        raise InstrumentError(f"{path}: shot {shot_id}: sha256 of the raw data does not match")
    truth, facts = None, None
    if "truth" in g:
        stored = json.loads(g["truth"].attrs["facts"])
        facts = ShotFacts.from_dict(stored, f"{path}: shot {shot_id}: facts") if stored else None
        truth = {k.replace(".", "_"): v[()] for k, v in g["truth/forces"].items()}
    seed = int(shot["seed"])
    return Entry(record, bool(shot["simulated"]), None if seed < 0 else seed, shot["scene"].decode(),
                 g["scene_text"][()].decode(), json.loads(g["settings"][()]), truth, facts,
                 _key(g), shot["start_time"].decode(), shot["project_version"].decode(), shot_id,
                 "as recorded by layout 1 (when archived, or the file's modification time for an import)")


def _key(g) -> str | None:
    """The shared key of a shot with truth (its shared group's name), else None."""
    if "truth" not in g:
        return None
    import h5py

    forces = h5py.h5o.get_info(g["truth/forces"].id).addr
    for key, s in g.file.get("shared", {}).items():
        if "forces" in s and h5py.h5o.get_info(s["forces"].id).addr == forces:
            return key
    return None
