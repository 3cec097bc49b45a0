"""reference/scene-keys.md: every key of rig.experiment.scene.SCHEMA, its unit or type, the
contact laws' bounds, defaults and meanings (rig.model.laws LawParameter), the other keys'
defaults (the keyword defaults of the classes the assembly builds from each table), the names
a key takes (materials, laws, methods), and each key's value in a published scene.

A scene key without a meaning in MEANINGS fails the build, so a new key is documented or the
site does not build."""
from __future__ import annotations

import inspect
import math

from reference_text import cell, names

EXAMPLE_SCENE = "ptfe52_magnetic"

# What each scene key means (the contact laws' keys carry their own, in LawParameter.doc).
MEANINGS = {
    "scene.name": "the scene's name (default: the file's stem)",
    "scene.description": "a line saying what the scene is",
    "scene.reference": "where the set-up is published",
    "chain.material": "the beads' material, from the material table",
    "chain.diameter": "each bead's diameter",
    "chain.mass": "each bead's mass (nominal; a study may draw each bead's own)",
    "chain.beads": "number of beads below the magnetic bead",
    "chain.magnetic_bead": "a magnetic bead on top, pulled by the ring magnet",
    "chain.previous_shots": "shots fired on this chain before this one (0-100): elastic-plastic contacts keep "
                            "the flattening each left (rig/experiment/history.py)",
    "chain.contact_law": "the contact law between neighbours",
    "chain.youngs_modulus": "the beads' Young's modulus (default: the material's)",
    "chain.poisson_ratio": "the beads' Poisson ratio (default: the material's)",
    "chain.magnetic_youngs_modulus": "the magnetic bead's Young's modulus (default: chrome steel's, assumed)",
    "chain.magnetic_poisson_ratio": "the magnetic bead's Poisson ratio (default: chrome steel's, assumed)",
    "striker.material": "the striker's material",
    "striker.mass": "the striker's mass",
    "striker.velocity": "the striker's speed at impact",
    "striker.diameter": "the striker's diameter",
    "striker.gap": "the distance the striker starts above the top bead (0: touching)",
    "magnet.force": "the ring magnet's pull on the top bead (a ring hanging on the bead: 2.38 N)",
    "magnet.position": "the ring's position, the pull then taken from the ring's field-gradient profile",
    "magnet.peak_force": "the profile's peak pull, with magnet.position",
    "magnet.schedule": "the pull varied in time: a list of [t (s), F (N)] points (one of force, position, schedule)",
    "magnet.hold": "how long the pull rested on the chain before the shot (600 s unless given; read by a yielding law)",
    "holder.bore": "the tube's inner diameter (a bead wider than it is refused)",
    "holder.outer_diameter": "the tube's outer diameter",
    "holder.length": "the tube's length",
    "holder.vertical": "the tube stands vertical (gravity along the chain)",
    "holder.drag": "viscous drag of the tube on each moving bead, -c v",
    "holder.friction": "dry friction of the tube on each moving bead, -F_f tanh(v / v_slip)",
    "holder.slip_speed": "the speed v_slip over which the friction builds up",
    "wall.material": "the wall's material",
    "wall.plate_mass": "the wall sensor's plate mass (a wall that is not rigid)",
    "wall.rod_stiffness": "the stiffness of the rod holding the plate",
    "wall_sensor.channel": "the scope channel the wall sensor drives",
    "wall_sensor.sensitivity": "the wall sensor's sensitivity",
    "wall_sensor.calibration_error": "relative sd of the sensitivity's error, drawn per shot",
    "wall_sensor.tau": "the time constant of the sensor's RC high-pass",
    "wall_sensor.noise": "sd of the sensor's additive noise",
    "gauges.NAME.bead": "the gauge bead, counted from the top, the magnetic bead not counted (1 to chain.beads)",
    "gauges.NAME.from_wall": "the gauge bead, counted from the wall instead (give one of bead, from_wall)",
    "gauges.NAME.channel": "the scope channel the gauge drives",
    "gauges.NAME.sensitivity": "the gauge's sensitivity",
    "gauges.NAME.calibration_error": "relative sd of the sensitivity's error, drawn per shot",
    "gauges.NAME.tau": "the time constant of the gauge's RC high-pass",
    "gauges.NAME.noise": "sd of the gauge's additive noise",
    "gauges.NAME.misalignment_sd": "sd of the gauge's position error, drawn per shot (the analysis never sees it)",
    "gauges.NAME.mass": "the gauge bead's true mass (caps and plate)",
    "scope.sample_interval": "the scope's sample interval",
    "scope.record_length": "points per record",
    "scope.mode": "acquisition mode: sample or average",
    "scope.averages": "records averaged in average mode",
    "scope.noise_floor": "what a displayed channel with nothing connected reads",
    "scope.model": "the scope model the files name",
    "scope.trigger.source": "the channel the edge trigger watches",
    "scope.trigger.level": "the trigger level",
    "scope.trigger.slope": "the trigger slope: rising or falling",
    "scope.trigger.pre_trigger": "the share of the record before the trigger (0..1)",
    "scope.trigger.mode": "normal: a shot that does not trigger gives no record; auto: it gives one all the same, "
                          "untriggered, its trigger point at the impact (the manuals' TRIGger:A:MODe NORMal and AUTO)",
    "scope.channels.CHn.volts_per_div": "the channel's vertical scale",
    "scope.channels.CHn.position": "the trace's position on screen (divisions)",
    "scope.channels.CHn.offset": "the channel's offset",
    "scope.channels.CHn.coupling": "DC or AC coupling",
    "scope.channels.CHn.bandwidth": "the bandwidth limit (one pole: rise time 0.35/BW)",
    "scope.channels.CHn.probe": "the probe's attenuation",
    "solver.method": "the integrator, from the solver's registry",
    "solver.accuracy": "the largest error of every recorded force relative to its peak (the accuracy contract)",
    "solver.duration": "how long the shot is simulated after the impact",
    "solver.sample_interval": "the interval the solver records forces at (not coarser than the scope's)",
}
WILDCARDS = {"gauges": "NAME", "channels": "CHn"}

def _kind(spec) -> str:
    if isinstance(spec, str):
        return spec
    return {float: "number", int: "whole number", str: "text", bool: "true/false", list: "list"}[spec]


def _leaves(node: dict, prefix: str = ""):
    for key, spec in node.items():
        name = WILDCARDS.get(prefix.rstrip(".").rsplit(".", 1)[-1], key) if key == "*" else key
        if isinstance(spec, dict):
            yield from _leaves(spec, f"{prefix}{name}.")
        else:
            yield f"{prefix}{name}", spec


def _example(values: dict, key: str):
    node = values
    for part in key.split("."):
        if part in ("NAME", "CHn") and isinstance(node, dict) and node:
            part = sorted(node)[0]
        if not isinstance(node, dict) or part not in node:
            return ""
        node = node[part]
    return f"`{node:g}`" if isinstance(node, float) else f"`{node}`"


def _constructors() -> dict:
    """{table: the classes the assembly builds from it} (rig/experiment/assembly.py): a key's
    default is its keyword's default there."""
    from instruments.devices.gauges import GaugeSettings
    from instruments.devices.oscilloscope import ChannelSettings, Oscilloscope, Timebase, Trigger
    from rig.experiment.settings import SolverSettings
    from rig.model.apparatus import Holder, RingMagnet
    from rig.model.parts import Striker, Wall

    return {"holder": (Holder,), "striker": (Striker,), "magnet": (RingMagnet,), "wall": (Wall,),
            "wall_sensor": (GaugeSettings,), "gauges.NAME": (GaugeSettings,), "scope": (Oscilloscope, Timebase),
            "scope.trigger": (Trigger,), "scope.channels.CHn": (ChannelSettings,), "solver": (SolverSettings,)}


def _default(constructors: dict, key: str) -> str:
    """The default of a scene key, from the keyword of the class built from its table; ""
    where there is none (the key is required, or None: computed, or absent)."""
    table, name = key.rsplit(".", 1)
    for cls in constructors.get(table, ()):
        parameter = inspect.signature(cls).parameters.get(name)
        if parameter is not None and parameter.default not in (inspect.Parameter.empty, None):
            value = parameter.default
            return f"`{value:g}`" if isinstance(value, float) else f"`{value}`"
    return ""


def scene_keys() -> str:
    from rig.experiment.scene import SCHEMA, load
    from rig.model.laws import CONTACT_LAWS, PARAMETERS
    from rig.model.materials import MATERIALS
    from rig.solver.methods import METHODS

    example = load(EXAMPLE_SCENE).values
    constructors = _constructors()
    allowed = {"chain.material": names(MATERIALS), "striker.material": names(MATERIALS),
               "wall.material": names(MATERIALS), "chain.contact_law": names(CONTACT_LAWS),
               "solver.method": names(METHODS)}
    rows, missing = [], []
    for key, spec in _leaves(SCHEMA):
        law = PARAMETERS.get(key.split(".", 1)[1]) if key.startswith("chain.") else None
        if law is not None:
            unit = "1 (plain number, SI)" if law.unit == "1" else law.unit
            lo = "(" if law.lo_open else "["
            bounds = f"{lo}{law.lo:g}, {'inf' if math.isinf(law.hi) else format(law.hi, 'g')}]"
            rows.append((key, unit, bounds, f"`{law.default:g}`", law.doc))
        elif key in MEANINGS:
            rows.append((key, _kind(spec), allowed.get(key, ""), _default(constructors, key), MEANINGS[key]))
        else:
            missing.append(key)
    if missing:
        raise SystemExit(f"docs/hooks/reference_scene_keys.py: scene keys without a meaning in MEANINGS: "
                         f"{', '.join(missing)}")
    lines = [
        "# Scene keys (generated)", "",
        "Every key a scene file (TOML) and `--set KEY=VALUE` take, written from the scene schema "
        "(`rig/experiment/scene.py`) and the contact laws' registry (`rig/model/laws/`) when the site "
        "is built. A quantity is written with its unit (`\"0.89 m/s\"`); a plain number given to "
        "`--set` is taken in the key's SI unit. Unknown keys, a quantity without its unit and a value "
        "outside its range are refused, naming the key.", "",
        "The contact laws' bounds and defaults are their LawParameters'; the other defaults are the "
        "keyword defaults of the classes the assembly builds from each table (`Holder`, `Striker`, "
        "`RingMagnet`, `Wall`, `GaugeSettings`, `Oscilloscope`, `Timebase`, `Trigger`, `ChannelSettings`, "
        "`SolverSettings`), blank where a key is required or computed when left out. The other keys' "
        "bounds are checked where the parts are built, and a bad value's one-line refusal names them. "
        f"*in {EXAMPLE_SCENE}* is the value in the published scene `{EXAMPLE_SCENE}`.", "",
        f"| key | unit or type | bounds or names | default | in {EXAMPLE_SCENE} | meaning |",
        "|---|---|---|---|---|---|",
    ]
    for key, unit, bounds, default, meaning in rows:
        lines.append(f"| `{key}` | {cell(unit)} | {cell(bounds)} | {default} | {_example(example, key)} | "
                     f"{cell(meaning)} |")
    lines += ["", "`NAME` is any gauge's name (`upper`, `lower` in the published scenes); `CHn` a channel, "
              "`CH1` to `CH4`.", "", "Contact laws: " + ", ".join(
                  f"`{name}` ({law.description})" for name, law in CONTACT_LAWS.items()), ""]
    return "\n".join(lines)
