"""A part's digest, which the master of layouts 3 and 4 records for each part it links to:
a part file replaced by another of the same name (another archive's, whose groups agree
with their own tables) is named by ``rig verify``, and a master whose links point into
another master's folder is refused an append."""
from __future__ import annotations

import hashlib
import json
from pathlib import Path

PART_DIGESTS = "part_digests"
"""Master root attribute: {part file name: part_digest of the groups it holds}, written with
each transaction (a master written before it has none): a part replaced by another of the
same name, whose groups agree with their own tables, is named by ``rig verify``."""


def part_digest(tables: dict) -> str:
    """SHA-256 over the tables of checksums (their stored text) of the groups a part holds
    that the master links to, ``{path in the master: text}`` ("/shot_000002",
    "/shared/scene_x"), in path order. A group's table holds the SHA-256 of every dataset,
    attribute and member list in it, so this one digest pins the part's whole content."""
    h = hashlib.sha256()
    for path in sorted(tables):
        h.update(json.dumps([path, tables[path]]).encode())
    return h.hexdigest()


def recorded_digests(f) -> dict:
    """{part file name: digest} the master records ({} for a master written before them)."""
    try:
        out = json.loads(f.attrs.get(PART_DIGESTS, "{}"))
    except ValueError:
        return {}  # its row of the root's table says it is damaged
    return out if isinstance(out, dict) else {}


def part_tables(f, written: dict | None = None) -> dict:
    """{path ("/shot_000002", "/shared/scene_x"): its table's text} of every shot and shared
    group in a part file ``f`` (open), as part_digest takes them; ``written``: {path: the
    text} of the shots' tables a writer has just written into ``f`` (None: read it), not
    read back."""
    from .stored import table_text

    given = written or {}
    out = {f"/{name}": given.get(f"/{name}") or table_text(f[name]) for name in f if name.startswith("shot_")}
    if "shared" in f:
        out.update({f"/shared/{key}": table_text(f["shared"][key]) for key in f["shared"]})
    return out


def linked_parts(f) -> dict:
    """{part file name: (its path as the master's links name it, relative to the master's
    folder ("shots.h5.d/shots_000001.h5"), the ids of the master's shots that link into it)}
    of every part a master of layout 3 or 4 links to."""
    out: dict = {}
    for name in f:
        target = _target(f, name) if name.startswith("shot_") else None
        if target is not None:
            out.setdefault(target.name, (target, []))[1].append(int(name.split("_", 1)[1]))
    for key in f.get("shared", ()):
        target = _target(f["shared"], key)
        if target is not None:
            out.setdefault(target.name, (target, []))
    return {name: (target, sorted(ids)) for name, (target, ids) in out.items()}


def swapped_parts(f, bad: set) -> list:
    """[(part file name, the master's shots linked into it)] of the parts whose groups'
    tables, read from the part itself, do not give the digest the master ``f`` records for
    it. Judged only where the master records the part's digest (one written before them:
    not judged), the part opens, and none of the master's shots in it is among those
    ``bad`` already (a damaged part has its rows)."""
    import h5py

    recorded = recorded_digests(f)
    if not recorded:
        return []
    try:
        parts = linked_parts(f)
    except Exception:  # noqa: BLE001 - an unreadable root: its own rows say so
        return []
    out = []
    base = Path(f.filename).parent
    for name, (relative, ids) in sorted(parts.items()):
        if name not in recorded or bad.intersection(ids):
            continue
        try:
            with h5py.File(base / relative, "r") as part:
                tables = part_tables(part)
        except Exception:  # noqa: BLE001 - a missing or unreadable part: its shots' rows say so
            continue
        if part_digest(tables) != recorded[name]:
            out.append((name, ids))
    return out


def linked_folder(f) -> str | None:
    """The folder the master's links point into (``shots.h5.d``), from its first link; None
    where it links to nothing."""
    target = next((t for t in (_target(f, name) for name in f) if t is not None), None)
    return None if target is None else target.parent.name


def _target(group, name: str) -> Path | None:
    """The file ``group[name]``'s external link names, as stored; None for another link."""
    import h5py

    link = group.get(name, getlink=True)
    return Path(link.filename) if isinstance(link, h5py.ExternalLink) else None
