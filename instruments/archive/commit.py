"""A transaction of layouts 3 and 4: the new shots into a part file of their own, written
whole beside the master, then a copy of the small master that links to them put in place.
A writer stopped between the two leaves a part no master names, which the next transaction
of the same first shot replaces. The file writes themselves (a copy or a new file, built in
memory, flushed and renamed into place) are the Archive's ``_transaction``, handed in."""
from __future__ import annotations

import contextlib
import json
from collections.abc import Callable
from pathlib import Path

from ..errors import InstrumentError
from ..files import cause
from .compact import LAYOUT4, LAYOUT4_TEXT, write_compact_entry
from .layout import LAYOUT, write_entry
from .part_digests import PART_DIGESTS, linked_folder, part_digest, part_tables, recorded_digests
from .parts import LAYOUT3, PARTS_TEXT, add_shots, folder, link_into, next_id, part_name, recorded_ranges, stored_shared
from .verify import root_seal

TEXTS = {LAYOUT3: PARTS_TEXT.format(version=3, groups=2) + "\n\n" + LAYOUT,
         LAYOUT4: PARTS_TEXT.format(version=4, groups=4) + "\n\n" + LAYOUT4_TEXT}
# a shot's writer, by layout: layout 4's returns the text of the shot's table (layout 3's, None)
WRITERS: dict[int, Callable[..., str | None]] = {LAYOUT3: write_entry, LAYOUT4: write_compact_entry}


def commit_parts(path: Path, entries: list, transaction, master=None, ids=None, part: str = "") -> list:
    """Append ``entries`` to the archive at ``path`` (``master``: its master, open, closed
    here once read; None for a new archive or one rewritten whole) in one transaction;
    returns their ids. ``part``: the part file's name where not that of its first shot
    (``rig upgrade``: a name no older part has, so the old master's parts stay whole until
    the new master is in place).
    ``transaction(fill, copy, target)`` writes a file whole (Archive._transaction). The
    shots are written in the master's layout (3 or 4; a new archive: 4)."""
    layout = LAYOUT4 if master is None else int(master.attrs.get("layout_version"))
    try:
        members = recorded_ranges(master) if master is not None else {"/": [], "/shared": [], "shot_ids": []}
        stored = stored_shared(master) if master is not None else {}
        linked = linked_folder(master) if master is not None and part == "" else None
    except Exception as exc:  # noqa: BLE001 - a damaged master: one line, nothing written
        raise InstrumentError(f"{path}: cannot append: {cause(exc)}") from None
    if linked is not None and linked != folder(path).name:
        master.close()
        raise InstrumentError(f"{path}: cannot append: its shots are links into {linked}, the folder of another "
                              f"archive's master (a master copied without its folder?); its new shots would go to "
                              f"{folder(path).name}: copy a master together with its folder, under the same name, "
                              f"or append to the archive that folder belongs to")
    start = next_id(members)
    ids = ids or [start + i for i in range(len(entries))]
    part = part or (part_name(ids[0]) if ids else part_name(start))
    where = folder(path)
    made = not where.exists()
    checked: dict = {}
    axes: dict = {}
    extra = (axes,) if layout == LAYOUT4 else ()  # layout 4: the time axes shared inside the part

    def fill(f):
        tables = {f"/shot_{shot_id:06d}": WRITERS[layout](f, shot_id, e, checked, stored, *extra)
                  for shot_id, e in zip(ids, entries)}  # the tables' texts as written (layout 4), not read back
        f.attrs.update({"NX_class": "NXroot", "layout_version": layout, "part_of": path.name})
        return (sorted(f["shared"]) if "shared" in f else []), part_digest(part_tables(f, tables))

    try:
        where.mkdir(exist_ok=True)
        new_shared, digest = transaction(fill, False, where / part)
    except BaseException:
        if made:
            with contextlib.suppress(OSError):
                where.rmdir()
        raise
    finally:
        if master is not None:
            master.close()
    def link(f):
        return _link(f, path.name, layout, part, ids, new_shared, members, digest)
    try:
        transaction(link, master is not None)  # a copy of the master, or a new one
    except BaseException:
        with contextlib.suppress(OSError):
            (where / part).unlink()
            if made:
                where.rmdir()
        raise
    return ids


def _link(f, master: str, layout: int, part: str, ids: list, new_shared: list, members: dict, digest: str) -> list:
    """The master's links to a new part's shots and shared groups, the part's digest
    (parts.PART_DIGESTS) and its root sealed (``members``: its member lists before, shots
    as ranges of ids, to which the new names are added)."""
    for shot_id in ids:
        name = f"shot_{shot_id:06d}"
        f[name] = link_into(master, part, f"/{name}")
    if new_shared:
        shared = f.require_group("shared")
        shared.attrs["NX_class"] = "NXcollection"
        for key in new_shared:
            shared[key] = link_into(master, part, f"/shared/{key}")
    f.attrs.update({"NX_class": "NXroot", "creator": "sonic-rig", "layout_version": layout,
                    "layout": TEXTS[layout], "file_name": master})
    f.attrs["default"] = f"shot_{max(ids):06d}" if ids else f.attrs.get("default", "")
    f.attrs[PART_DIGESTS] = json.dumps({**recorded_digests(f), part: digest}, sort_keys=True)
    root_seal(f, add_shots(members, ids, new_shared))
    return ids
