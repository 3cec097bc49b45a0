"""A group's table of checksums as stored (digest.py computes them, compare.py compares them): its
text, its rows, and the shared groups it links to, each read once by a caller that needs
several of them."""
from __future__ import annotations

import json
from typing import TYPE_CHECKING

from .values import attribute_or

if TYPE_CHECKING:
    import h5py

TABLE = "checksums"  # the dataset (layout 4: the attribute) that holds a group's table


def stored_table(group: h5py.Group) -> str:
    """The text of ``group``'s table as stored (an attribute, or a dataset)."""
    text = attribute_or(group, TABLE)
    if text is None:  # a table before layout 4: a dataset
        text = group[TABLE][()]
    return text.decode() if isinstance(text, bytes) else str(text)


def table_text(group: h5py.Group) -> str | None:
    """stored_table(), None where it cannot be read (damage() then says why)."""
    try:
        return stored_table(group)
    except Exception:  # noqa: BLE001
        return None


def stored_rows(text: str | None) -> dict:
    """The rows of a stored table's ``text`` ({row key: row}); empty where it is unreadable
    or no JSON object (damage() says why)."""
    try:
        rows = json.loads(text or "{}")
    except ValueError:
        return {}
    return rows if isinstance(rows, dict) else {}


def links_below(rows: dict, under: str) -> set:
    """The groups below ``under`` (e.g. "/shared/") that a table's ``rows`` link to, by name
    ({"scene_ab12"})."""
    return {v[len("link:") + len(under):].split("/", 1)[0] for v in rows.values()
            if isinstance(v, str) and v.startswith("link:" + under)}


def linked_groups(group: h5py.Group, under: str, text: str | None = None) -> set:
    """links_below of ``group``'s stored table; empty when the table is unreadable (its check
    says why). ``text``: the stored table's text where the caller has read it."""
    return links_below(stored_rows(table_text(group) if text is None else text), under)
