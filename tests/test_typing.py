"""The packages are typed: mypy, with the configuration stated in pyproject.toml ([tool.mypy]),
finds no error in rig/, instruments/ and numerics/; each ships a py.typed marker; the lazy facade shows
type checkers the very names it loads (its ``if TYPE_CHECKING:`` block against ``_PUBLIC``),
and ``import rig`` still loads none of the layers.

mypy runs here, in the suite, not as a step of its own: with its cache (.mypy_cache) empty,
as in a fresh clone, it took 16 s of CPU (41 s of wall time on two cores shared with a load
of 7); with the cache, a few seconds (docs/how-to/contributing.md)."""
import ast
import subprocess
import sys
from pathlib import Path

if sys.version_info >= (3, 11):
    import tomllib
else:
    import tomli as tomllib

ROOT = Path(__file__).resolve().parents[1]


def facade_names() -> tuple[dict, dict]:
    """({module: names} of rig/__init__.py's _PUBLIC table, {module: names} its TYPE_CHECKING
    block imports), read with ast."""
    tree = ast.parse((ROOT / "rig" / "__init__.py").read_text())
    public, checked = {}, {}
    for node in tree.body:
        if isinstance(node, ast.Assign) and any(getattr(t, "id", "") == "_PUBLIC" for t in node.targets):
            public = {k: set(v) for k, v in ast.literal_eval(node.value).items()}
        if isinstance(node, ast.If) and ast.unparse(node.test) == "TYPE_CHECKING":
            for child in node.body:
                assert isinstance(child, ast.ImportFrom), ast.unparse(child)
                for alias in child.names:
                    assert alias.asname == alias.name, f"{alias.name}: re-exported as itself (X as X)"
                    checked.setdefault(child.module, set()).add(alias.name)
    return public, checked


def test_the_facade_shows_checkers_its_public_names():
    public, checked = facade_names()
    assert public and checked == public
    import rig

    assert set(rig.__all__) == set().union(*checked.values())


def test_import_rig_loads_no_layer_and_no_numba():
    code = "import sys, rig; print(sorted(m for m in sys.modules if m.split('.')[0] in ('rig', 'numba', 'typing')))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, cwd=ROOT)
    assert out.stdout.strip() == "['rig']", out.stdout


def test_every_package_ships_a_py_typed_marker():
    data = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]["package-data"]
    for package in ("rig", "instruments", "numerics"):
        assert (ROOT / package / "py.typed").is_file() and "py.typed" in data[package]


def test_mypy_finds_no_error_in_rig_instruments_and_numerics():
    out = subprocess.run([sys.executable, "-m", "mypy"], check=False, capture_output=True, text=True, cwd=ROOT)
    assert out.returncode == 0, out.stdout[-4000:] + out.stderr[-2000:]
    assert "Success: no issues found" in out.stdout
