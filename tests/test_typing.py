"""The packages are typed: mypy, with the configuration stated in pyproject.toml ([tool.mypy]),
finds no error in rig/, instruments/ and numerics/; each ships a py.typed marker; a lazy
facade (rig, instruments and its two wings) shows type checkers the very names it loads (its
``if TYPE_CHECKING:`` block against its __all__), and ``import rig`` still loads none of the
layers.

mypy runs here, in the suite, not as a step of its own: with its cache (.mypy_cache) empty,
as in a fresh clone, it took 16 s of CPU (41 s of wall time on two cores shared with a load
of 7); with the cache, a few seconds (docs/how-to/contributing.md)."""
import ast
import importlib
import importlib.util
import subprocess
import sys
from pathlib import Path

import pytest

if sys.version_info >= (3, 11):
    import tomllib
else:
    import tomli as tomllib

ROOT = Path(__file__).resolve().parents[1]


FACADES = ("rig", "instruments", "instruments.analysis", "instruments.devices")
"""The packages whose public names load on first use (PEP 562 __getattr__)."""


def checked_names(package: str) -> dict:
    """{name: its defining module} of the ``if TYPE_CHECKING:`` block of ``package``'s
    __init__.py, read with ast (relative imports resolved)."""
    path = ROOT.joinpath(*package.split("."), "__init__.py")
    out = {}
    for node in ast.parse(path.read_text()).body:
        if isinstance(node, ast.If) and ast.unparse(node.test) == "TYPE_CHECKING":
            for child in node.body:
                assert isinstance(child, ast.ImportFrom), ast.unparse(child)
                module = importlib.util.resolve_name("." * child.level + (child.module or ""), package)
                for alias in child.names:
                    assert alias.asname == alias.name, f"{package}: {alias.name} re-exported as itself (X as X)"
                    out[alias.name] = module
    return out


@pytest.mark.parametrize("package", FACADES)
def test_a_lazy_facade_shows_checkers_its_public_names(package):
    """The TYPE_CHECKING block names what __all__ names, each from the module the facade
    loads it from."""
    facade, checked = importlib.import_module(package), checked_names(package)
    assert checked and sorted(checked) == sorted(facade.__all__)
    for name, module in checked.items():
        assert getattr(facade, name) is getattr(importlib.import_module(module), name), f"{package}.{name}"


def test_the_parts_constructors_as_checkers_see_them_are_the_dataclasses():
    """A part's ``if TYPE_CHECKING: def __init__`` (quantities with their units, as the
    documentation writes them) has its dataclass's fields, in order, with their defaults."""
    from dataclasses import MISSING, fields

    parts = importlib.import_module("rig.model.parts")
    seen = []
    for node in ast.parse(Path(parts.__file__).read_text()).body:
        init = next((f for child in getattr(node, "body", ()) if isinstance(child, ast.If)
                     and ast.unparse(child.test) == "TYPE_CHECKING" for f in child.body
                     if isinstance(f, ast.FunctionDef) and f.name == "__init__"), None)
        if init is None:
            continue
        cls, args = getattr(parts, node.name), init.args.args[1:]
        defaults = [None] * (len(args) - len(init.args.defaults)) + init.args.defaults
        declared = [(a.arg, MISSING if d is None else eval(ast.unparse(d), vars(parts)))
                    for a, d in zip(args, defaults)]
        assert declared == [(f.name, f.default) for f in fields(cls) if f.init], node.name
        seen.append(node.name)
    assert {"Bead", "MagneticBead", "GaugeBead", "Striker", "Wall"} <= set(seen)


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
