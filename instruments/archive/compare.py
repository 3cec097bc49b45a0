"""A group's stored table of checksums (digest.py) compared with the file as it now reads:
each damaged, missing or added dataset, attribute or member list named in a line. HDF5's
own fletcher32 checks raise while the values are read; the row of the item that raised
says so and is named damaged."""
from __future__ import annotations

import json
from typing import TYPE_CHECKING

from .digest import DIGEST, first_line, rows, table
from .hashes import sha
from .stored import TABLE, stored_table
from .values import attribute_or

if TYPE_CHECKING:
    import h5py


def damage(group: h5py.Group, linked: dict, read=None, known: dict | None = None, text: str | None = None,
           hashed: dict | None = None) -> list:
    """What differs between ``group``'s stored table and the file: a list of
    "path: what is wrong" lines, empty when every item matches. ``read`` (a test of a row's
    key, e.g. ``lambda key: not key.startswith("data/")``): only the rows a reader reads are
    computed, item by item, without walking the rest (``known``: {row key: its row} that a
    reader computed from the values it read, not read again); where one differs, the whole
    table is compared and the lines about those rows given. ``text``: the stored table's
    text where the caller has read it (stored_table), not read again. ``hashed``: as for
    table(), where the whole table is compared."""
    try:
        text = stored_table(group) if text is None else text
        if sha(text.encode()) != _sealed_digest(group):
            return [f"{TABLE}: the table of checksums (or the attribute {DIGEST}) is damaged"]
        stored = json.loads(text)
    except Exception as exc:  # noqa: BLE001
        return [f"{TABLE}: unreadable ({first_line(exc)})"]
    if read is not None:
        keys = [k for k in stored if read(k)]
        if rows(group, [k for k in keys if k not in (known or {})], linked, stored, known) == \
                {k: stored[k] for k in keys}:
            return []
        found = _differences(stored, table(group, linked, hashed=hashed))
        return [p for p in found if read(p.removeprefix("attribute ").split(": ", 1)[0])] or found
    return _differences(stored, table(group, linked, hashed=hashed))


def _sealed_digest(group) -> str:
    """The group's attribute ``sha256`` ("" where it has none)."""
    return str(attribute_or(group, DIGEST, ""))


def _differences(stored: dict, now: dict) -> list:
    out = []
    for key in sorted(set(stored) | set(now)):
        kind = "attribute " if "@" in key else ""
        if key not in now:
            out.append(f"{kind}{key}: missing")
        elif key not in stored:
            out.append(f"{kind}{key}: not in the table of checksums (added or renamed)")
        elif now[key] != stored[key]:
            cause = now[key][len("unreadable: "):] if now[key].startswith("unreadable") else "SHA-256 differs"
            out.append(f"{kind}{key}: damaged ({cause})")
    return out
