"""reference/api.md: mkdocstrings pages for the names rig/__init__.py's facade exports and
every public module of the instruments package."""
from __future__ import annotations

import ast
import importlib
import inspect
import pkgutil

from reference_text import ROOT


def _facade() -> dict:
    """{module: names} of rig/__init__.py's lazy facade, read from its source (its table is
    data: reading it does not import the modules)."""
    tree = ast.parse((ROOT / "rig" / "__init__.py").read_text())
    for node in tree.body:
        if isinstance(node, ast.AnnAssign | ast.Assign) and isinstance(node.value, ast.Dict):
            return ast.literal_eval(node.value)
    raise SystemExit("docs/hooks/reference_api.py: rig/__init__.py has no facade table")


def public_modules(package: str):
    """The dotted names of ``package``'s public modules (no part of the name begins with ``_``)."""
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
    for module in sorted(public_modules("instruments")):
        lines += [f"::: {module}", "    options:", "      heading_level: 3", "      members_order: source",
                  "      filters: [\"!^_\"]", ""]
    return "\n".join(lines)
