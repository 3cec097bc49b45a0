"""What the generated Reference pages share: the project's root, and a value written into
a markdown table's cell."""
from __future__ import annotations

from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def cell(text) -> str:
    """``text`` on one line, its pipes escaped: one cell of a markdown table."""
    return str(text).replace("|", "\\|").replace("\n", " ")


def names(values) -> str:
    """The values, sorted, each as code, comma-separated."""
    return ", ".join(f"`{v}`" for v in sorted(values))
