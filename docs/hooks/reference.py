"""mkdocs hook: the Reference pages written from the code at each build.

- reference/scene-keys.md: every key of rig.experiment.scene.SCHEMA, its unit or type, the
  contact laws' bounds, defaults and meanings (rig.model.laws LawParameter), the other
  keys' defaults (the keyword defaults of the classes the assembly builds from each table),
  the names a key takes (materials, laws, methods), and each key's value in a published scene;
- reference/commands.md: every command and flag of rig.cli.build_parser();
- reference/api.md: mkdocstrings pages for the names rig/__init__.py's facade exports and
  every public module of the instruments package;
- reference/archive.md: the archive layout, from instruments.archive's LAYOUT and the
  docstrings of the archive's modules.

A scene key without a meaning below fails the build, so a new key is documented or the
site does not build.
"""
from __future__ import annotations

import argparse
import ast
import importlib
import inspect
import math
import pkgutil
from pathlib import Path

from mkdocs.structure.files import File

ROOT = Path(__file__).resolve().parents[2]
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


def _cell(text) -> str:
    return str(text).replace("|", "\\|").replace("\n", " ")


def _names(values) -> str:
    return ", ".join(f"`{v}`" for v in sorted(values))


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
    allowed = {"chain.material": _names(MATERIALS), "striker.material": _names(MATERIALS),
               "wall.material": _names(MATERIALS), "chain.contact_law": _names(CONTACT_LAWS),
               "solver.method": _names(METHODS)}
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
        raise SystemExit(f"docs/hooks/reference.py: scene keys without a meaning in MEANINGS: {', '.join(missing)}")
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
        lines.append(f"| `{key}` | {_cell(unit)} | {_cell(bounds)} | {default} | {_example(example, key)} | "
                     f"{_cell(meaning)} |")
    lines += ["", "`NAME` is any gauge's name (`upper`, `lower` in the published scenes); `CHn` a channel, "
              "`CH1` to `CH4`.", "", "Contact laws: " + ", ".join(
                  f"`{name}` ({law.description})" for name, law in CONTACT_LAWS.items()), ""]
    return "\n".join(lines)


def _subcommands(parser: argparse.ArgumentParser):
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            helps = {a.dest: a.help for a in action._choices_actions}
            for name, sub in action.choices.items():
                yield name, helps.get(name), sub


def _command(lines: list, path: str, summary, parser: argparse.ArgumentParser):
    lines += [f"## `{path}`", ""]
    if summary or parser.description:
        lines += [_cell(summary or parser.description), ""]
    lines += ["```text", parser.format_usage().strip(), "```", ""]
    rows = []
    for action in parser._actions:
        if isinstance(action, (argparse._HelpAction, argparse._SubParsersAction)):
            continue
        name = ", ".join(f"`{o}`" for o in action.option_strings) or f"`{action.metavar or action.dest}`"
        choices = _names(action.choices) if action.choices else ""
        default = "" if action.default in (None, False, argparse.SUPPRESS) or action.option_strings == [] \
            else f"`{action.default}`"
        rows.append(f"| {name} | {choices} | {default} | {_cell(action.help or '')} |")
    if rows:
        lines += ["| argument | choices | default | what |", "|---|---|---|---|", *rows, ""]
    for name, help_text, sub in _subcommands(parser):
        _command(lines, f"{path} {name}", help_text, sub)


def commands() -> str:
    from rig.cli import build_parser

    parser = build_parser()
    lines = ["# Commands and flags (generated)", "",
             "Every `rig` command and its flags, written from the command line's parser "
             "(`rig.cli.build_parser`) when the site is built. `rig COMMAND --help` prints the same. "
             "A bad value is one line naming the flag, the value and what is allowed, with exit status 2.", ""]
    for name, help_text, sub in _subcommands(parser):
        _command(lines, f"rig {name}", help_text, sub)
    return "\n".join(lines)


def _facade() -> dict:
    """{module: names} of rig/__init__.py's lazy facade, read from its source (its table is
    data: reading it does not import the modules)."""
    tree = ast.parse((ROOT / "rig" / "__init__.py").read_text())
    for node in tree.body:
        if isinstance(node, ast.AnnAssign | ast.Assign) and isinstance(node.value, ast.Dict):
            return ast.literal_eval(node.value)
    raise SystemExit("docs/hooks/reference.py: rig/__init__.py has no facade table")


def _public_modules(package: str):
    root = importlib.import_module(package)
    for info in pkgutil.walk_packages(root.__path__, f"{package}."):
        if not any(part.startswith("_") for part in info.name.split(".")):
            yield info.name


def _assigns(module, name: str) -> bool:
    """Whether ``module``'s source binds ``name`` by a plain assignment (``NAME = ...``)."""
    tree = ast.parse(inspect.getsource(module))
    targets = (t for node in tree.body if isinstance(node, ast.Assign | ast.AnnAssign)
               for t in (node.targets if isinstance(node, ast.Assign) else [node.target]))
    return any(isinstance(t, ast.Name) and t.id == name for t in targets)


def _defining_module(module: str, name: str) -> str:
    """Where ``name`` (exported by the facade from ``module``) is defined: a class's or a
    function's own module; for data, the loaded rig module that assigns the very object."""
    import sys

    obj = getattr(importlib.import_module(module), name)
    if inspect.isclass(obj) or inspect.isfunction(obj):
        return obj.__module__
    for candidate in sorted(m for m in sys.modules if m == "rig" or m.startswith("rig.")):
        loaded = sys.modules[candidate]
        if getattr(loaded, name, None) is obj and getattr(loaded, "__file__", None) and _assigns(loaded, name):
            return candidate
    return module


def api() -> str:
    lines = ["# Python API (generated)", "",
             "## `rig`", "",
             "`import rig` loads each of these names on first use; they live in the modules below. "
             "Bad input raises `rig.RigError` (a `ValueError`) with one line naming the field, the value and "
             "what is allowed.", ""]
    for module, names in sorted(_facade().items()):
        lines += [f"### `{module}`", ""]
        for name in names:
            lines += [f"::: {_defining_module(module, name)}.{name}", "    options:", "      heading_level: 4", ""]
    lines += ["## `instruments`", "",
              "The measurement side; it never imports `rig`. Every public module, with its public names.", ""]
    for module in sorted(_public_modules("instruments")):
        lines += [f"::: {module}", "    options:", "      heading_level: 3", "      members_order: source",
                  "      filters: [\"!^_\"]", ""]
    return "\n".join(lines)


def archive() -> str:
    from instruments import archive as archive_module
    from instruments.archive import CURRENT_LAYOUT, LAYOUT

    lines = ["# Archive layout (generated)", "",
             f"Written from the archive's code when the site is built: layout version {CURRENT_LAYOUT}, "
             "as every archive states it in its root attribute `layout` (and `layout_version`). "
             "[The archive's guarantees](../explanation/archive.md) explain the checksums and the "
             "transactions.", "", "## The layout", "", "```text", inspect.cleandoc(LAYOUT), "```", ""]
    modules = [archive_module.__name__] + sorted(
        name for name in _public_modules("instruments") if "archive" in name and name != archive_module.__name__)
    for name in modules:
        doc = inspect.getdoc(importlib.import_module(name))
        if doc:
            lines += [f"## `{name}`", "", "```text", doc, "```", ""]
    return "\n".join(lines)


PAGES = {"reference/scene-keys.md": scene_keys, "reference/commands.md": commands,
         "reference/api.md": api, "reference/archive.md": archive}


def on_files(files, config):
    """Add the generated pages to the site."""
    import sys

    if str(ROOT) not in sys.path:
        sys.path.insert(0, str(ROOT))
    for path, write in PAGES.items():
        files.append(File.generated(config, path, content=write()))
    return files
