"""reference/archive.md: the archive layout, from instruments.archive's LAYOUT and the
docstrings of the archive's modules."""
from __future__ import annotations

import importlib
import inspect

from reference_api import public_modules


def archive() -> str:
    from instruments import archive as archive_module
    from instruments.archive import CURRENT_LAYOUT, LAYOUT

    lines = ["# Archive layout (generated)", "",
             f"Written from the archive's code when the site is built: layout version {CURRENT_LAYOUT}, "
             "as every archive states it in its root attribute `layout` (and `layout_version`). "
             "[The archive's guarantees](../explanation/archive.md) explain the checksums and the "
             "transactions.", "", "## The layout", "", "```text", inspect.cleandoc(LAYOUT), "```", ""]
    modules = [archive_module.__name__] + sorted(
        name for name in public_modules("instruments") if "archive" in name and name != archive_module.__name__)
    for name in modules:
        doc = inspect.getdoc(importlib.import_module(name))
        if doc:
            lines += [f"## `{name}`", "", "```text", doc, "```", ""]
    return "\n".join(lines)
