"""The observations file of `rig fit --observations FILE`: TOML, one table per observation.

    [[observation]]
    kind = "speed"              # a name in rig.fit.observations.kinds.KINDS
    value = "129 m/s"           # with its unit (a plain number for a ratio or a count),
    sd = "13 m/s"               #   or value = 129, sd = 13, unit = "m/s"
    scene = "ptfe52_gravity"    # optional: the command's SCENE (a name, or a file beside this one)
    set = ["magnet.force=2.38 N"]   # optional: the shot's scene overrides
    gauge = "upper"             # where the kind is taken at a gauge: a gauge of the scene, or "wall"
    limit = "at least"          # optional: the observation says only that the figure is at least
                                #   (or "at most") the value; 0 residual on that side

    [[observation]]             # a ratio: the figure `of` of this shot over that of the `over_` shot
    kind = "ratio"
    of = "peak"
    value = 2.0
    sd = 0.25
    scene = "ptfe52_magnetic"
    over_scene = "ptfe52_gravity"   # optional: the same scene; over_set: its overrides
    gauge = "upper"

Every entry is checked before any solve: a mistake is one line naming the entry, the field,
its value and what is allowed.
"""
from __future__ import annotations

import sys
from dataclasses import replace
from pathlib import Path

from rig.errors import RigError, invalid, lookup
from rig.experiment import scene as scene_io
from rig.fit.observations.kinds import KINDS, LIMITS, WALL, Kind, Observation, Shot
from rig.units import number, quantity

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

SD_FLOOR = 1e-9  # the smallest sd an observation may have, relative to its value
FIELDS = ("kind", "value", "sd", "unit", "scene", "set", "gauge", "of", "over_scene", "over_set", "limit")


def _figure(entry: dict, name: str, kind: Kind, field: str) -> float:
    """The entry's value or sd in the kind's SI unit."""
    text, unit = entry.get(name), entry.get("unit")
    if text is None:
        raise invalid(field, None, f"needed: the observation's {name} in {kind.unit}")
    if isinstance(text, bool) or not isinstance(text, (str, int, float)):
        raise invalid(field, text, f"a number or a quantity in {kind.unit}")
    if kind.unit == "1":
        if unit not in (None, "1", ""):
            raise invalid(field.rsplit(".", 1)[0] + ".unit", unit, "this kind is a pure number: no unit")
        return number(text, field, "a plain number (this kind has no unit)")
    if unit is not None:
        if isinstance(text, str):
            raise invalid(field, text, f"a plain number where unit = {unit!r} is given")
        text = f"{text} {unit}"
    return quantity(text, kind.unit, field)


def _shot(entry: dict, prefix: str, default_scene: str, folder: Path, field: str) -> Shot:
    name = entry.get(f"{prefix}scene", default_scene)
    overrides = entry.get(f"{prefix}set", [])
    if not isinstance(name, str):
        raise invalid(f"{field}.{prefix}scene", name, "a scene's name or file")
    if not isinstance(overrides, list) or not all(isinstance(o, str) for o in overrides):
        raise invalid(f"{field}.{prefix}set", overrides, 'a list of "KEY=VALUE" texts')
    beside = folder / name
    if name != default_scene and beside.is_file():
        name = str(beside)
    try:
        scene_io.load(name, overrides)
    except RigError as exc:
        raise RigError(f"{field}: {exc}") from None
    return Shot(name, tuple(overrides))


def _gauge(entry: dict, shots: tuple, field: str) -> str:
    gauge = entry.get("gauge")
    for shot in shots:
        values = scene_io.load(shot.scene, shot.overrides).values
        known = sorted(values.get("gauges") or {}) + ([WALL] if values.get("wall_sensor") else [])
        if gauge not in known:
            raise invalid(f"{field}.gauge", gauge, f"where this kind is taken: one of {', '.join(known)} "
                                                   f"(in {shot.scene})")
    return str(gauge)  # one of a scene's gauge names


def observation(entry, default_scene: str, folder: Path, field: str) -> Observation:
    """One entry of the file (module doc), checked."""
    if not isinstance(entry, dict):
        raise invalid(field, entry, "a table of kind, value, sd, ...")
    for k in entry:
        if k not in FIELDS:
            raise invalid(f"{field}.{k}", entry[k], f"not a field of an observation; known: {', '.join(FIELDS)}")
    name = entry.get("kind")
    kind = lookup(KINDS, name, f"{field}.kind", Kind)
    name = str(name).strip().lower()
    value, sd = _figure(entry, "value", kind, f"{field}.value"), _figure(entry, "sd", kind, f"{field}.sd")
    if not sd > 0:
        raise invalid(f"{field}.sd", entry["sd"], "> 0: a standard uncertainty (an exact figure cannot be fitted)")
    if sd < SD_FLOOR * abs(value) or sd < 1e-100:
        raise invalid(f"{field}.sd", entry["sd"], f">= {SD_FLOOR:g} of the value ({value:.6g} {kind.unit}): no "
                                                 f"measurement is finer, and the fit's weight 1/sd^2 would overflow")
    shot = _shot(entry, "", default_scene, folder, field)
    of, over = "", None
    if name == "ratio":
        of = str(entry.get("of", "peak")).strip().lower()
        inner = KINDS.get(of)
        if inner is None or of == "ratio" or not inner.at_gauge:
            raise invalid(f"{field}.of", entry.get("of"), "the figure a ratio divides: one of "
                          + ", ".join(k for k, v in KINDS.items() if v.at_gauge and k != "ratio"))
        over = _shot(entry, "over_", shot.scene, folder, field)
        if over == shot:
            raise invalid(f"{field}.over_set", list(over.overrides), "the ratio's two shots are the same shot: "
                          "give over_scene or over_set")
    elif "of" in entry or "over_scene" in entry or "over_set" in entry:
        bad = next(k for k in ("of", "over_scene", "over_set") if k in entry)
        raise invalid(f"{field}.{bad}", entry[bad], "only a ratio has it")
    gauge = ""
    if kind.at_gauge:
        gauge = _gauge(entry, (shot,) if over is None else (shot, over), field)
    elif "gauge" in entry:
        raise invalid(f"{field}.gauge", entry["gauge"], f"a {name} is not taken at one gauge: leave it out")
    if name == "pulses" and not value >= 1:
        raise invalid(f"{field}.value", entry["value"], "at least 1 (the leading pulse)")
    if not (value >= 0 if name == "tail" else value > 0):
        raise invalid(f"{field}.value", entry["value"], ">= 0" if name == "tail" else "> 0")
    limit = entry.get("limit", "")
    if limit != "" and limit not in LIMITS:
        raise invalid(f"{field}.limit", limit, f"one of {', '.join(repr(k) for k in LIMITS)} (or leave it out: a "
                                                "measured value)")
    return Observation(name, value, sd, kind.unit, shot, gauge, of, over, str(limit), field)


def read_observations(path, default_scene: str) -> tuple:
    """The observations of a file (module doc), each checked; RigError names the entry."""
    path = Path(path)
    try:
        raw = tomllib.loads(path.read_text())
    except OSError as exc:
        raise invalid("--observations", str(path), f"cannot read it ({exc.strerror})") from None
    except UnicodeDecodeError:
        raise invalid("--observations", str(path), "not a text file (TOML)") from None
    except tomllib.TOMLDecodeError as exc:
        raise invalid("--observations", str(path), f"not TOML ({exc})") from None
    extra = [k for k in raw if k != "observation"]
    if extra:
        raise invalid(f"{path.name}: {extra[0]}", raw[extra[0]], "the file holds [[observation]] tables only")
    entries = raw.get("observation")
    if not isinstance(entries, list) or not entries:
        raise invalid("--observations", str(path), "no [[observation]] table in it")
    out = tuple(observation(e, default_scene, path.parent, f"{path.name}: observation {i + 1}")
                for i, e in enumerate(entries))
    for i, o in enumerate(out):
        same = next((j for j in range(i) if replace(out[j], label="") == replace(o, label="")), None)
        if same is not None:
            raise invalid(f"{path.name}: observation {i + 1}", f"{o.kind} = {entries[i].get('value')!r}",
                          f"repeats observation {same + 1} (the same figure of the same shot, value and sd): an "
                          f"observation counted twice would narrow the intervals without a new measurement")
    return out
