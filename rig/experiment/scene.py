"""Scene files: a TOML description of one shot, every quantity with its unit.

A scene has the tables [scene], [chain], [striker], [magnet] (optional), [holder],
[wall], [wall_sensor] (optional), [gauges.NAME] (any number), [scope] with
[scope.trigger] and [scope.channels.CHn], and [solver]. The keys and their units are in
SCHEMA. Unknown keys, a quantity without its unit, and a value outside its range are
refused naming the key. Overrides use dotted keys ("striker.velocity=1.2"); a plain number
is taken in the key's SI unit (m/s here).
"""
from __future__ import annotations

import math
import os
import sys
from dataclasses import dataclass, field
from pathlib import Path

from rig.errors import RigError, invalid
from rig.model.laws import PARAMETERS as LAW_PARAMETERS
from rig.units import check_digits, is_non_finite, is_number, number, quantity, whole

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

GAUGE_KEYS = {"bead": int, "from_wall": int, "channel": str, "sensitivity": "V/N",
              "calibration_error": float, "tau": "s", "noise": "V", "misalignment_sd": "m", "mass": "kg"}
CHANNEL_KEYS = {"volts_per_div": "V", "position": float, "offset": "V", "coupling": str,
                "bandwidth": "Hz", "probe": float}
SCHEMA = {
    "scene": {"name": str, "description": str, "reference": str},
    "chain": {"material": str, "diameter": "m", "mass": "kg", "beads": int,
              "magnetic_bead": bool, "contact_law": str,
              **{key: p.scene_spec for key, p in LAW_PARAMETERS.items()},  # the contact laws' (rig.model.laws)
              "youngs_modulus": "Pa", "poisson_ratio": float, "previous_shots": int,
              "magnetic_youngs_modulus": "Pa", "magnetic_poisson_ratio": float},
    "striker": {"material": str, "mass": "kg", "velocity": "m/s", "diameter": "m", "gap": "m"},
    "magnet": {"force": "N", "position": "m", "peak_force": "N", "schedule": list, "hold": "s"},
    "holder": {"bore": "m", "outer_diameter": "m", "length": "m", "vertical": bool,
               "drag": "kg/s", "friction": "N", "slip_speed": "m/s"},
    "wall": {"material": str, "plate_mass": "kg", "rod_stiffness": "N/m"},
    "wall_sensor": {"channel": str, "sensitivity": "V/N", "calibration_error": float,
                    "tau": "s", "noise": "V"},
    "gauges": {"*": GAUGE_KEYS},
    "scope": {"sample_interval": "s", "record_length": int, "mode": str, "averages": int,
              "noise_floor": "V", "model": str,
              "trigger": {"source": str, "level": "V", "slope": str, "pre_trigger": float, "mode": str},
              "channels": {"*": CHANNEL_KEYS}},
    "solver": {"method": str, "accuracy": float, "duration": "s", "sample_interval": "s"},
}
PUBLISHED_SCENES = Path(__file__).resolve().parent.parent / "scenes"  # package data


def find_scene(name_or_path) -> Path:
    """A path to a .toml file, or the name of a published scene (rig/scenes/, e.g. ptfe52_magnetic)."""
    if not isinstance(name_or_path, (str, os.PathLike)) or not str(name_or_path).strip():
        raise invalid("scene", name_or_path, "a scene file's path or a published scene's name, e.g. ptfe52_magnetic")
    p = Path(name_or_path)
    if p.is_file():
        return p
    if p.suffix == ".toml" or len(p.parts) > 1:
        raise invalid("scene", str(name_or_path), "no such scene file")
    hits = sorted(PUBLISHED_SCENES.rglob(f"{p.name}.toml"))
    if not hits:
        known = sorted(q.stem for q in PUBLISHED_SCENES.rglob("*.toml"))
        raise invalid("scene", str(name_or_path), f"neither a scene file nor a published scene; known scenes: "
                                                  f"{', '.join(known)}")
    return hits[0]


@dataclass(frozen=True, eq=False)
class Scene:
    """A scene as fired: its name, the TOML text as written, the overrides applied
    ("key=value" items) and the validated values (nested tables, quantities in SI)."""

    name: str
    text: str
    overrides: tuple = ()
    values: dict = field(default_factory=dict)

    def with_values(self, values: dict) -> Scene:
        """The same scene with other values (a study's shot: the same text and overrides)."""
        return Scene(self.name, self.text, self.overrides, values)


def read_raw(name_or_path) -> tuple:
    """(text, raw TOML table) of a scene file, its scene.name defaulting to the file's stem;
    nothing checked against SCHEMA yet."""
    path = find_scene(name_or_path)
    try:
        text = path.read_text()
    except UnicodeDecodeError:
        raise invalid("scene", str(path), "not a text (TOML) scene file") from None
    try:
        raw = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise RigError(f"scene {path}: not valid TOML ({exc})") from None
    raw.setdefault("scene", {}).setdefault("name", path.stem)
    return text, raw


def load(name_or_path, overrides=()) -> Scene:
    """Parse, override and validate a scene file (a path, or a published scene's name)."""
    text, raw = read_raw(name_or_path)
    allowed = 'a list of "key=value" texts, e.g. ["striker.velocity=1.2 m/s"]'
    if isinstance(overrides, (str, bytes)) or not hasattr(overrides, "__iter__"):
        raise invalid("overrides", overrides, allowed)
    overrides = tuple(overrides)
    if not all(isinstance(item, str) for item in overrides):
        raise invalid("overrides", overrides, allowed)
    for item in overrides:
        apply_override(raw, item)
    values = convert(raw)
    return Scene(values["scene"]["name"], text, overrides, values)


def apply_override(raw: dict, item: str):
    """Set ``key=value`` in a scene's raw TOML table (the value a quantity of the key's SI
    unit when it is a plain number), checked against SCHEMA."""
    if "=" not in item:
        raise invalid("--set", item, "expected key=value, e.g. striker.velocity=1.2")
    key, value = (s.strip() for s in item.split("=", 1))
    parts = key.split(".")
    spec = _spec_for(parts)
    node = raw
    for p in parts[:-1]:
        node = node.setdefault(p, {})
        if not isinstance(node, dict):
            raise invalid("--set", key, "not a table in this scene")
    node[parts[-1]] = _typed(value, spec, key)


def schema_node(key: str):
    """The SCHEMA entry of a dotted key: a type, a unit string, or a table (dict).
    KeyError(i) names the first part of the key that the schema does not know."""
    node: object = SCHEMA
    for i, p in enumerate(key.split(".")):
        if not isinstance(node, dict) or (p not in node and "*" not in node):
            raise KeyError(i)
        node = node.get(p, node.get("*"))
    return node


def key_spec(key: str):
    """The SCHEMA entry (a type or a unit string) of a dotted scene key; RigError naming
    the keys known where it goes wrong, or that it is a table."""
    return _spec_for(key.split("."))


def unknown_key(key: str, extra: tuple = ()) -> str:
    """Why the dotted ``key`` is not a scene key: "unknown key; known in TABLE: ..." (the
    keys of the table where the schema stops knowing it, and those of ``extra``, dotted
    keys known elsewhere, that lie in the same table)."""
    parts = key.split(".")
    try:
        schema_node(key)
        return "unknown key"
    except KeyError as exc:
        where = ".".join(parts[:exc.args[0]])
    parent = schema_node(where) if where else SCHEMA
    known = [k for k in parent if k != "*"] if isinstance(parent, dict) else []
    known += [k.removeprefix(f"{where}.") for k in extra if k.rpartition(".")[0] == where]
    return f"unknown key; known in {where or 'the scene'}: {', '.join(dict.fromkeys(known)) or 'none'}"


def _spec_for(parts):
    key = ".".join(parts)
    try:
        node = schema_node(key)
    except KeyError:
        raise invalid("scene key", key, unknown_key(key)) from None
    if isinstance(node, dict):
        raise invalid("scene key", key, "is a table; set one of its keys")
    return node


def _typed(value: str, spec, key):
    """An override's text as its TOML value: a bool, a whole number, a number, or a
    quantity's text (a plain number taken in the key's SI unit)."""
    if spec is bool:
        if value.lower() not in ("true", "false"):
            raise invalid(key, value, "true or false")
        return value.lower() == "true"
    if spec is int:
        return whole(value, key)
    if spec is float:
        return number(value, key)
    if isinstance(spec, str):  # a quantity: a plain number is in SI
        check_digits(value, key)
        if not (is_number(value) or is_non_finite(value)):
            return value  # text with a unit, for quantity()
        x = float(value)
        if not math.isfinite(x):
            raise invalid(key, value, f"a finite number (plain number: {spec})")
        return f"{x!r} {spec}"
    return value


def convert(raw: dict) -> dict:
    """Validate keys against SCHEMA and convert quantities to SI floats."""
    return _convert(raw, SCHEMA, "")


def _convert(node, spec, prefix):
    if not isinstance(node, dict):
        raise invalid(prefix.rstrip("."), node, "expected a table")
    out = {}
    for key, value in node.items():
        sub = spec.get(key, spec.get("*"))
        name = f"{prefix}{key}"
        if sub is None:
            raise invalid("scene key", name, f"unknown key; known here: {', '.join(k for k in spec if k != '*')}")
        if isinstance(sub, dict):
            out[key] = _convert(value, sub, name + ".")
        elif isinstance(sub, str):
            if key == "bandwidth" and value == "full":
                out[key] = None
            else:
                out[key] = quantity(value, sub, name)
        elif sub is list:
            out[key] = _schedule(value, name)
        elif sub is float:
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
                raise invalid(name, value, "a number")
            out[key] = float(value)
        elif not isinstance(value, sub) or (sub is int and isinstance(value, bool)):
            raise invalid(name, value, f"expected {sub.__name__}")
        else:
            out[key] = value
    return out


def _schedule(value, name):
    """[["0 ms", "2.38 N"], ["1 ms", "4.25 N"], ...] -> ((s, N), ...)."""
    if not isinstance(value, list) or not value:
        raise invalid(name, value, 'a list of ["time", "force"] pairs, e.g. [["0 ms", "2.38 N"]]')
    pairs = []
    for i, pair in enumerate(value):
        if not isinstance(pair, list) or len(pair) != 2:
            raise invalid(f"{name}[{i}]", pair, 'a ["time", "force"] pair')
        pairs.append((quantity(pair[0], "s", f"{name}[{i}].time"),
                      quantity(pair[1], "N", f"{name}[{i}].force")))
    return tuple(pairs)
