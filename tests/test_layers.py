"""The layers of docs/architecture.md hold, read with ``ast`` from every .py file under rig/,
instruments/ and numerics/: imports point down (function-level and literal ``import_module`` ones
too), imports form no cycle (module-level, function-level and TYPE_CHECKING ones alike), numerics
imports neither rig nor instruments, instruments never import rig and its rooms import only the
rooms ROOMS allows (the devices never the analysis), the facade is lazy and gives rig only
``__version__``, no private name crosses modules. The checker is tested on a planted tree."""
import ast
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
# a module may import its own layer or a lower one; model and theory, study and lab share a rank but stay apart
RANKS = {"numerics": -1, "instruments": 0, "rig.errors": 1, "rig.units": 2, "rig.memo": 2, "rig.model": 3,
         "rig.theory": 3, "rig.solver": 4, "rig.experiment": 5, "rig.viz": 6, "rig.fit": 7, "rig.study": 8,
         "rig.lab": 8, "rig.bench": 9, "rig.cli": 10}
APART = {frozenset({"rig.model", "rig.theory"}), frozenset({"rig.study", "rig.lab"})}
PACKAGES = ("rig", "instruments", "numerics")  # the project's top-level packages
# the rooms of instruments/ (a subpackage, or a module at its top) and the rooms each may import: the
# devices never import the analysis, the analysis reads the devices' records; the kernels shared by both
# wings, the records, rails and errors are beneath them
ROOMS = {
    "instruments": {"instruments.analysis", "instruments.devices", "instruments.facade"},
    "instruments.errors": set(), "instruments.records": set(), "instruments.rails": set(),
    "instruments.facade": set(), "instruments.files": {"instruments.errors"},
    "instruments._kernels": {"numerics"}, "instruments.precompile": {"numerics"},
    "instruments.streams": {"instruments._kernels", "instruments.errors"},
    "instruments.devices": {"instruments._kernels", "instruments.errors", "instruments.facade", "instruments.records",
                            "numerics"},
    "instruments.analysis": {"instruments._kernels", "instruments.devices", "instruments.errors", "instruments.facade",
                             "instruments.rails", "instruments.records", "numerics"},
    "instruments.formats": {"instruments.errors", "instruments.files", "instruments.rails", "instruments.records"},
    "instruments.archive": {"instruments.errors", "instruments.files", "instruments.records"},
    "instruments.scpi": set(), "instruments.transports": {"instruments.errors"},
    "instruments.virtual_scope": {"instruments.devices", "instruments.errors", "instruments.records",
                                  "instruments.scpi", "instruments.transports"},
}
HEAVY = {"numba", "scipy", "pint", "pyvista", "vtk", "vtkmodules", "matplotlib", "dask", "h5py"}


def layer(module: str):
    """The layer of a project module (its longest prefix in RANKS), or None."""
    hits = [k for k in RANKS if module == k or module.startswith(k + ".")]
    return max(hits, key=len) if hits else None


def room(module: str):
    """The room of an instruments module (instruments.X: its subpackage or top-level module), or None."""
    parts = module.split(".")
    return ".".join(parts[:2]) if parts[0] == "instruments" else None


def modules(root: Path) -> dict:
    """{module name: path} of every .py file under each of PACKAGES in root."""
    out = {}
    for pkg in PACKAGES:
        for path in sorted((root / pkg).rglob("*.py")):
            parts = list(path.relative_to(root).with_suffix("").parts)
            out[".".join(parts[:-1] if parts[-1] == "__init__" else parts)] = path
    return out


def _literal_module(call: ast.Call):
    """The module named by a literal ``import_module("x")`` or ``__import__("x")`` (for an
    f-string, the package its literal head names), or None."""
    func, arg = call.func, call.args[0] if call.args else None
    if getattr(func, "attr", getattr(func, "id", None)) not in ("import_module", "__import__"):
        return None
    if isinstance(arg, ast.Constant) and isinstance(arg.value, str):
        return arg.value
    if isinstance(arg, ast.JoinedStr) and arg.values and isinstance(arg.values[0], ast.Constant):
        return arg.values[0].value.rpartition(".")[0] or None
    return None


def imports(name: str, path: Path):
    """Yield (module, imported name or None, line, runs at import time) for one file."""
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]

    def visit(node, top):
        for child in ast.iter_child_nodes(node):
            if isinstance(child, ast.Import):
                for alias in child.names:
                    yield alias.name, None, child.lineno, top
            elif isinstance(child, ast.ImportFrom):
                base = child.module or ""
                if child.level:  # relative: resolve against this module's package
                    parts = package.split(".")[: len(package.split(".")) - child.level + 1]
                    base = ".".join(parts + ([child.module] if child.module else []))
                for alias in child.names:
                    yield base, alias.name, child.lineno, top
            elif isinstance(child, ast.Call) and _literal_module(child):
                yield _literal_module(child), None, child.lineno, top
            lazy = isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda)) or (
                isinstance(child, ast.If) and "TYPE_CHECKING" in ast.unparse(child.test))  # not run
            yield from visit(child, top and not lazy)

    yield from visit(ast.parse(path.read_text(), str(path)), True)


def _private(part: str) -> bool:  # dunders (__version__, __main__) are public
    return part.startswith("_") and not part.startswith("__")


def check_layers(root: Path) -> list:
    """Every violation under root, one line each: 'file:line: edge: why'."""
    mods = modules(root)
    problems, graph, every = [], {m: set() for m in mods}, {m: set() for m in mods}
    for name, path in mods.items():
        here, rel = layer(name), path.relative_to(root).as_posix()
        if here is None and name != "rig":
            problems.append(f"{rel}: {name} is in no layer (add it to RANKS and docs/architecture.md)")
        if room(name) and room(name) not in ROOMS:
            problems.append(f"{rel}: {name} is in no room of instruments (add it to ROOMS and docs/architecture.md)")
        for target, item, line, top in imports(name, path):
            full = f"{target}.{item}" if item and f"{target}.{item}" in mods else target
            if full.split(".")[0] not in PACKAGES or full == name:
                continue
            there, edge = layer(full), f"{rel}:{line}: {name} imports {full}"
            if name == "rig":
                if top and full != "rig":
                    problems.append(f"{edge}: the facade loads its layers lazily (_PUBLIC), never at import")
            elif here == "instruments" and full.split(".")[0] == "rig":
                problems.append(f"{edge}: instruments never import rig")
            elif here == "numerics" and there != "numerics":
                problems.append(f"{edge}: numerics imports neither rig nor instruments")
            elif room(name) in ROOMS and (room(full) or there) not in ROOMS[room(name)] | {room(name)}:
                problems.append(f"{edge}: {room(name)} may not import {room(full) or there} (ROOMS)")
            elif full == "rig" and item != "__version__":
                problems.append(f"{edge}{f' {item}' if item else ''}: only __version__ comes from the rig "
                                "facade; name the defining module")
            elif here and there and (RANKS[there] > RANKS[here] or frozenset({here, there}) in APART):
                down = f"{here.removeprefix('rig.')} may not import {there.removeprefix('rig.')}"
                problems.append(f"{edge}: {down}")
            parts = full.split(".")
            hidden = [i for i, part in enumerate(parts) if _private(part)]
            owner = ".".join(parts[: hidden[-1]]) if hidden else None
            if owner is not None and name != owner and not name.startswith(owner + "."):
                problems.append(f"{edge}: {parts[hidden[-1]]} is private to {owner}")
            if item and _private(item) and full == target:
                problems.append(f"{edge}: {item} is private to {full}")
            if full in mods:
                every[name].add(full)
                if top:
                    graph[name].add(full)
    return problems + [_cycle_line(c, graph) for c in cycles(every)]


def _cycle_line(cycle: list, graph: dict) -> str:
    """One import cycle, said as a path, and whether only module-level imports close it."""
    lazy = any(b not in graph[a] for a, b in zip(cycle, cycle[1:]))
    return f"import cycle{' (function-level or TYPE_CHECKING imports too)' if lazy else ''}: {' -> '.join(cycle)}"


def cycles(graph: dict) -> list:
    """A cycle path (a -> b -> a) per strongly connected group of modules (Tarjan)."""
    index, low, stack, groups = {}, {}, [], []

    def connect(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        for w in sorted(graph[v]):
            if w not in index:
                connect(w)
                low[v] = min(low[v], low[w])
            elif w in stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            group = set()
            while not group or v not in group:
                group.add(stack.pop())
            if len(group) > 1:
                groups.append(group)

    for v in sorted(graph):
        if v not in index:
            connect(v)
    return sorted(_shortest_cycle(graph, group) for group in groups)


def _shortest_cycle(graph: dict, group: set) -> list:
    """The shortest path from the group's first module back to itself (breadth first)."""
    start = min(group)
    paths, queue = {start: [start]}, [start]
    for v in queue:
        for w in sorted(graph[v] & group):
            if w == start:
                return paths[v] + [start]
            if w not in paths:
                paths[w] = paths[v] + [w]
                queue.append(w)


def test_the_tree_keeps_its_layers():
    problems = check_layers(ROOT)
    assert not problems, "layer violations (docs/architecture.md):\n" + "\n".join(problems)


def test_the_checker_finds_planted_violations(tmp_path):
    files = {
        "rig/__init__.py": "from rig.model import x\n", "rig/errors.py": "from rig.units import q\n",
        "rig/memo.py": "from rig.units import q\n", "rig/cli/ok.py": "from rig import __version__, errors\n",
        "rig/model/x.py": "from rig.solver.solve import solve\n", "rig/theory/t.py": "from ..model import x\n",
        "rig/model/lazy.py": "import importlib\ndef f():\n    importlib.import_module('rig.viz.figures')\n",
        "rig/solver/solve.py": "def solve():\n    from . import c\n",
        "rig/solver/a.py": "from rig.solver.b import y\ndef _helper(): pass\n", "rig/solver/b.py": "from . import a\n",
        "rig/solver/c.py": "def f():\n    from rig.solver import solve\n",  # lazy, but c <-> solve is a cycle
        "rig/experiment/e.py": "from instruments._kernels.peaks import p\nfrom rig.solver.a import _helper\n"
                               "from rig import Chain\n",
        "rig/extra/z.py": "", "rig/viz/figures.py": "", "instruments/_kernels/peaks.py": "p = 1\n",
        "instruments/y.py": "import rig\nfrom instruments._kernels import peaks\n",
        "numerics/n.py": "from instruments import y\n",
        "instruments/devices/d.py": "from instruments.analysis.a import p\n",
        "instruments/analysis/a.py": "from instruments.devices.d import q\nfrom instruments.archive import Archive\n",
    }
    for rel, text in files.items():
        (tmp_path / rel).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / rel).write_text(text)
    expected = [
        "rig/__init__.py:1: rig imports rig.model.x: the facade loads its layers lazily",
        "rig/errors.py:1: rig.errors imports rig.units: errors may not import units",
        "rig/model/x.py:1: rig.model.x imports rig.solver.solve: model may not import solver",
        "rig/model/lazy.py:3: rig.model.lazy imports rig.viz.figures: model may not import viz",
        "rig/theory/t.py:1: rig.theory.t imports rig.model.x: theory may not import model",
        "rig/experiment/e.py:1: rig.experiment.e imports instruments._kernels.peaks: "
        "_kernels is private to instruments",
        "rig/experiment/e.py:2: rig.experiment.e imports rig.solver.a: _helper is private to rig.solver.a",
        "rig/experiment/e.py:3: rig.experiment.e imports rig Chain: only __version__ comes from the rig facade",
        "rig/extra/z.py: rig.extra.z is in no layer",
        "instruments/y.py:1: instruments.y imports rig: instruments never import rig",
        "numerics/n.py:1: numerics.n imports instruments.y: numerics imports neither rig nor instruments",
        "instruments/y.py: instruments.y is in no room of instruments",
        "instruments/devices/d.py:1: instruments.devices.d imports instruments.analysis.a: instruments.devices may not "
        "import instruments.analysis",
        "instruments/analysis/a.py:2: instruments.analysis.a imports instruments.archive: instruments.analysis may not "
        "import instruments.archive",
        "import cycle: instruments.analysis.a -> instruments.devices.d -> instruments.analysis.a",
        "import cycle: rig.solver.a -> rig.solver.b -> rig.solver.a",
        "import cycle (function-level or TYPE_CHECKING imports too): rig.solver.c -> rig.solver.solve -> rig.solver.c",
    ]
    found = check_layers(tmp_path)  # each expected line, and nothing else
    for line in expected:
        assert any(p.startswith(line) for p in found), f"not reported: {line}\nfound:\n" + "\n".join(found)
    assert len(found) == len(expected), "\n".join(found)


def test_the_command_line_parser_loads_nothing_heavy():
    code = ("import sys, rig.cli\nrig.cli.build_parser()\n"
            f"print(' '.join(sorted({{m.split('.')[0] for m in sys.modules}} & set({sorted(HEAVY)!r}))))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, check=True)
    assert out.stdout.split() == [], f"loaded by import rig.cli + build_parser(): {out.stdout.strip()}"
