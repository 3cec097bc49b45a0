"""The layers of docs/architecture.md hold: every import points down (function-level
imports included), module-level imports form no cycle, instruments never import rig, and
no private name is imported across modules. The checker is tested on a planted tree too."""
import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
# rank of each layer: a module may import its own layer or a lower one; model and theory
# share a rank but may not import each other
RANKS = {"instruments": 0, "rig.errors": 1, "rig.units": 1, "rig.memo": 1, "rig.model": 2, "rig.theory": 2,
         "rig.solver": 3, "rig.experiment": 4, "rig.viz": 5, "rig.study": 6, "rig.bench": 7, "rig.cli": 8}
APART = {("rig.model", "rig.theory"), ("rig.theory", "rig.model")}


def layer(module: str):
    """The layer of a project module (the longest prefix in RANKS), or None (not ours)."""
    hits = [k for k in RANKS if module == k or module.startswith(k + ".")]
    return max(hits, key=len) if hits else None


def modules(root: Path) -> dict:
    """{module name: path} of every .py file under root/rig and root/instruments."""
    out = {}
    for pkg in ("rig", "instruments"):
        for path in sorted((root / pkg).rglob("*.py")):
            parts = list(path.relative_to(root).with_suffix("").parts)
            if parts[-1] == "__init__":
                parts = parts[:-1]
            out[".".join(parts)] = path
    return out


def imports(name: str, path: Path):
    """(imported module, imported name or None, line, at module level) of one file."""
    tree = ast.parse(path.read_text())
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    top = {id(n) for n in tree.body}
    top |= {id(c) for n in tree.body if isinstance(n, (ast.If, ast.Try)) for c in ast.walk(n)}
    for node in ast.walk(tree):
        level = id(node) in top
        if isinstance(node, ast.Import):
            for alias in node.names:
                yield alias.name, None, node.lineno, level
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parts = package.split(".")[: len(package.split(".")) - node.level + 1]
                base = ".".join(parts + ([node.module] if node.module else []))
            for alias in node.names:
                yield base, alias.name, node.lineno, level
        elif (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute)
              and node.func.attr == "import_module" and node.args and isinstance(node.args[0], ast.Constant)
              and isinstance(node.args[0].value, str)):
            yield node.args[0].value, None, node.lineno, False


def check_layers(root: Path) -> list:
    """Every violation found under root, one line each."""
    mods = modules(root)
    problems, graph = [], {m: set() for m in mods}
    for name, path in mods.items():
        here = layer(name)
        for target, item, line, top in imports(name, path):
            full = f"{target}.{item}" if item and f"{target}.{item}" in mods else target
            there = layer(full)
            where = f"{path.relative_to(root)}:{line}"
            if name == "rig":  # the facade names its layers as strings, loaded lazily
                if there is not None and item != "annotations":
                    problems.append(f"{where}: rig/__init__ imports {full} (use the lazy _PUBLIC table)")
                continue
            if here == "instruments" and full.split(".")[0] == "rig":
                problems.append(f"{where}: {name} imports {full}: instruments never import rig")
            if full == "rig" and item not in (None, "__version__"):
                problems.append(f"{where}: {name} imports {item} from the rig facade (name its module)")
            if there is None or here is None:
                continue
            if RANKS[there] > RANKS[here] or (here, there) in APART:
                problems.append(f"{where}: {name} imports {full}: {here} may not import {there}")
            private = [p for p in full.split(".") if p.startswith("_") and not p.startswith("__")]
            if item and item.startswith("_") and not item.startswith("__") and full == target:
                private.append(item)
            if private and not name.startswith(full.split("._")[0]):
                problems.append(f"{where}: {name} imports the private {'.'.join(private)} of {full}")
            if top and full in mods and full != name:
                graph[name].add(full)
    return problems + [f"import cycle: {' -> '.join(c)}" for c in cycles(graph)]


def cycles(graph: dict) -> list:
    """One cycle (as a path) per strongly connected group of more than one module."""
    index, low, stack, on, found, counter = {}, {}, [], set(), [], [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in graph.get(v, ()):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            group = []
            while True:
                w = stack.pop()
                on.discard(w)
                group.append(w)
                if w == v:
                    break
            if len(group) > 1:
                found.append(sorted(group) + [sorted(group)[0]])

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return found


def test_the_tree_keeps_its_layers():
    assert check_layers(ROOT) == []


def test_the_checker_finds_planted_violations(tmp_path):
    files = {"rig/__init__.py": "", "rig/model/__init__.py": "", "rig/solver/__init__.py": "",
             "rig/model/chain.py": "def f():\n    from rig.solver.solve import solve\n",
             "rig/solver/solve.py": "from rig.model import chain\n",
             "rig/solver/a.py": "from rig.solver.b import x\n", "rig/solver/b.py": "from rig.solver import a\nx = 1\n",
             "rig/theory/__init__.py": "from rig.model.chain import f\n",
             "rig/experiment/__init__.py": "from instruments._kernels.peaks import local_maxima\n",
             "instruments/__init__.py": "", "instruments/y.py": "import rig\n",
             "instruments/_kernels/__init__.py": "", "instruments/_kernels/peaks.py": "local_maxima = 1\n"}
    for rel, text in files.items():
        (tmp_path / rel).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / rel).write_text(text)
    found = "\n".join(check_layers(tmp_path))
    assert "rig.model.chain imports rig.solver.solve: rig.model may not import rig.solver" in found
    assert "instruments.y imports rig: instruments never import rig" in found
    assert "rig.theory imports rig.model.chain: rig.theory may not import rig.model" in found
    assert "import cycle: rig.solver.a -> rig.solver.b -> rig.solver.a" in found
    assert "imports the private _kernels" in found
