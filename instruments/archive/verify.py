"""Checking an open archive: the root's attributes and member lists, each shared group once,
then each shot, against their tables of SHA-256 checksums (instruments/archive/digest.py).
Every problem is a row naming the shot (or the shots of a shared group) and the dataset or
attribute; an object added or deleted anywhere is named by its path ("added: /foo",
"missing: /shot_000003/data/CH2"); a damaged file gives rows, never an exception.

The root's table has two versions. Version 1 (archives written before the member lists were
recorded): the attribute ``checksums``, {attribute: SHA-256} of the root's other attributes.
Version 2 adds the attribute ``members``, the names in the root group and in ``/shared`` (the
two groups that no table of their own covers); its SHA-256 is a row of ``checksums`` like
any attribute's. A layout-3 master lists its shots as ranges of ids (``"shot_ids": [[1,
10000]]``, ``compact``), so that the attribute an append rewrites stays small. An archive
without ``members`` is checked as version 1; its next append
(or ``rig upgrade``) writes version 2. From layout 4 on, the root's table also holds a row
per attribute of ``/shared`` ("/shared@NX_class")."""
from __future__ import annotations

import json
import re
from typing import TYPE_CHECKING

from .addresses import address
from .compare import damage
from .digest import sha
from .links import OpenParts
from .members import expanded
from .part_digests import swapped_parts
from .stored import TABLE, linked_groups, table_text

if TYPE_CHECKING:
    import h5py

ROOT_TABLE = "checksums"  # root attribute: {attribute: SHA-256} of the root's other attributes
MEMBERS = "members"  # root attribute (version 2): {"/": root's member names, "/shared": shared's}
_ADDED = "not in the table of checksums"  # how compare.damage words an added item
SHARED_ATTRS_SINCE = 4  # the layout from which the root's table covers /shared's attributes


def root_seal(f: h5py.File, members: dict | None = None):
    """Write the root's member lists (``members``, {"/": names, "/shared": names}, or its
    ``compact`` form, where the writer knows them: a large root is not walked) and its table
    (after its other attributes)."""
    f.attrs[MEMBERS] = json.dumps(members or _members(f), sort_keys=True)
    f.attrs[ROOT_TABLE] = json.dumps(_root_rows(f), sort_keys=True)


def sealed_members(f: h5py.File) -> bool:
    """Whether the root's table is of version 2 (it records the member lists)."""
    return MEMBERS in f.attrs


def _members(f) -> dict:
    out = {"/": sorted(f)}
    if "shared" in f:
        out["/shared"] = sorted(f["shared"])
    return out


def member_changes(f: h5py.File) -> tuple:
    """(added, missing): the paths ("/foo", "/shot_000002") of the objects added to or
    deleted from the root or /shared since the root was sealed; ([], []) for a version-1
    table. Where the member list itself is missing, unreadable or damaged (its SHA-256 is
    not the one the root's table holds), what no checksum covers is named instead
    (``uncovered``)."""
    try:
        stored = member_list(f)
    except ValueError:  # its own row (root_damage) says it is missing or damaged
        return uncovered(f), []
    if stored is None:
        return [], []
    now = _members(f)
    added, missing = [], []
    for group in sorted(set(stored) | set(now)):
        before, after = set(stored.get(group, [])), set(now.get(group, []))
        prefix = group.rstrip("/") + "/"
        added += [prefix + n for n in sorted(after - before)]
        missing += [prefix + n for n in sorted(before - after)]
    parents = set(added) | set(missing)  # a whole /shared added or deleted: its members are not listed again
    def drop(p):
        return p.rsplit("/", 1)[0] in parents
    return [p for p in added if not drop(p)], [p for p in missing if not drop(p)]


def member_list(f, expand: bool = True) -> dict | None:
    """The root's recorded member lists ({group: names}; not ``expand``: shots as ranges of
    ids where the root records them so, ``compact``); None for a version-1 table.
    ValueError where they are missing though the root's table names them, unreadable, or
    not what the root's table holds the SHA-256 of."""
    try:
        rows = json.loads(f.attrs[ROOT_TABLE])
    except Exception:  # noqa: BLE001 - the table's own row says why
        rows = {}
    if not sealed_members(f):
        if MEMBERS in rows:
            raise ValueError(f"@{MEMBERS} missing")
        return None
    if MEMBERS in rows and rows[MEMBERS] != _root_rows(f).get(MEMBERS):
        raise ValueError(f"@{MEMBERS} damaged")
    try:
        stored = json.loads(f.attrs[MEMBERS])
    except Exception as exc:  # noqa: BLE001
        raise ValueError(f"@{MEMBERS} unreadable ({_line(exc)})") from None
    if not isinstance(stored, dict):
        raise ValueError(f"@{MEMBERS} is not a JSON object")
    try:
        return expanded(stored) if expand else stored
    except Exception as exc:  # noqa: BLE001 - ranges that are not pairs of numbers
        raise ValueError(f"@{MEMBERS} unreadable ({_line(exc)})") from None


def uncovered(f: h5py.File) -> list:
    """The paths in the root and in /shared that no checksum covers, for an archive whose
    member list cannot be trusted: at the root, what is neither /shared nor a shot group
    with its own table; in /shared, a group no shot's table links to."""
    linked, out = set(), []
    for name in sorted(f):
        obj = f[name]
        if name.startswith("shot_") and hasattr(obj, "keys") and (TABLE in obj or TABLE in obj.attrs):
            linked |= linked_groups(obj, "/shared/")
        elif name != "shared":
            out.append(f"/{name}")
    if "shared" in f and hasattr(f["shared"], "keys"):
        out += [f"/shared/{k}" for k in sorted(f["shared"]) if k not in linked]
    return out


def root_damage(f: h5py.File) -> list:
    try:
        stored = json.loads(f.attrs[ROOT_TABLE])
        now = _root_rows(f)
    except Exception as exc:  # noqa: BLE001
        return [f"attribute @{ROOT_TABLE}: unreadable ({_line(exc)})"]
    return [f"attribute {k if k.startswith('/') else '@' + k}: damaged" for k in sorted(set(stored) | set(now))
            if stored.get(k) != now.get(k)]


def _root_rows(f) -> dict:
    """{attribute: SHA-256} of the root's attributes; from layout 4 on, also of /shared's
    ("/shared@NX_class"), which no group's own table covers."""
    out = {}
    for k in sorted(f.attrs):
        if k != ROOT_TABLE:
            out[k] = _value_sha(f.attrs[k])
    if f.attrs.get("layout_version", 0) >= SHARED_ATTRS_SINCE and "shared" in f:
        shared = f["shared"]
        out.update({f"/shared@{k}": _value_sha(shared.attrs[k]) for k in sorted(shared.attrs)})
    return out


def _value_sha(v) -> str:
    return sha(repr(v.tolist() if hasattr(v, "tolist") else v).encode())


def shot_names(f: h5py.File) -> list:
    return sorted(k for k in f if k.startswith("shot_"))


def check(f: h5py.File) -> dict:
    """{"shots", "ok", "bad"}: bad rows {"shot", "shots", "where", "reason"}; "shots" counts
    the shots the root lists, a deleted shot (bad) included."""
    bad = [_row(None, _item(r) if _item(r).startswith("/") else "/" + _item(r), r) for r in root_damage(f)]
    try:
        names = shot_names(f)
        added, missing = member_changes(f)
    except Exception as exc:  # noqa: BLE001
        return {"shots": 0, "ok": 0, "bad": bad + [_row(None, "/", f"the root group is unreadable ({_line(exc)})")]}
    for path in added:
        bad.append(_row(None, path, f"added: {path}"))
    names = [n for n in names if "/" + n not in added]  # a group added at the root is no shot
    shot_bad = {_shot_id(p) for p in missing if _shot_id(p) is not None}
    for path in missing:
        bad.append(_row(_shot_id(path), path, f"missing: {path}"))
    shared, problems, linked = _shared_groups(f, bad, added)
    users: dict = {}
    hashed: dict = {}  # rows of the datasets that several shots share (a part's time axis): read once (digest.table)
    with OpenParts() as parts:  # each part opened once, directly
        for name in names:
            shot_id = int(name.split("_", 1)[1])
            try:
                g = parts.group(f, name)
                text = table_text(g)
                found = named(damage(g, linked, text=text, hashed=hashed), f"/{name}")
                for key in linked_groups(g, "/shared/", text):
                    users.setdefault(key, []).append(shot_id)
            except Exception as exc:  # noqa: BLE001
                found = [f"unreadable ({_line(exc)})"]
            for p in found:
                bad.append(_row(shot_id, _where(p, f"/{name}"), p))
                shot_bad.add(shot_id)
    for path in missing:  # a deleted shared group: the shots that linked to it
        key = path.removeprefix("/shared/")
        if path.startswith("/shared/") and key in users:
            problems[key] = [f"missing: {path}"]
            bad[:] = [b for b in bad if b["where"] != path]
    for key, found in problems.items():
        ids = sorted(users.get(key, []))
        shot_bad.update(ids)
        for p in found:
            bad.append({"shot": None, "shots": ids, "where": _where(p, f"/shared/{key}"),
                        "reason": f"{p} (shared by shot{'' if len(ids) == 1 else 's'} "
                                  f"{', '.join(map(str, ids)) or '-'})"})
    for part, ids in swapped_parts(f, shot_bad):
        shot_bad.update(ids)
        bad.append({"shot": None, "shots": ids, "where": part,
                    "reason": f"part {part} is not the one this archive wrote: its groups' tables differ from the "
                              f"digest the master holds (replaced by another file of that name, or another "
                              f"archive's part?) (shot{'' if len(ids) == 1 else 's'} "
                              f"{', '.join(map(str, ids)) or '-'})"})
    listed = len(names) + sum(1 for p in missing if _shot_id(p) is not None)
    return {"shots": listed, "ok": listed - len(shot_bad), "bad": bad}


def named(problems: list, prefix: str) -> list:
    """compare.damage's lines for the group at ``prefix``, with each object added or
    deleted (a dataset, or a group: its member-list row "X/") named once by its path
    ("missing: /shot_000003/data/CH2") and the lines it alone explains left out: the member
    list of its group, its own attributes and members."""
    moved = {}
    for p in problems:
        head, _, what = p.partition(": ")
        if not head.startswith("attribute ") and head != "/" and (what == "missing" or what.startswith(_ADDED)):
            moved[head.rstrip("/")] = "missing" if what == "missing" else "added"
    if not moved:
        return problems
    def inside(item):
        return any(item.startswith((k + "/", k + "@")) for k in moved)
    parents = {(k.rsplit("/", 1)[0] + "/") if "/" in k else "/" for k in moved}
    out = []
    for p in problems:
        head, _, what = p.partition(": ")
        item = head.removeprefix("attribute ")
        own = None if head.startswith("attribute ") else item.rstrip("/")
        if own in moved:
            if not inside(own):  # not inside another object added or deleted
                out.append(f"{moved[own]}: {prefix}/{own}")
        elif not inside(item) and not (item in parents and what.startswith("damaged")):
            out.append(p)  # not explained by what was added or deleted
    return out


def _where(problem: str, prefix: str) -> str:
    """The path a problem line is about, inside the group at ``prefix``."""
    if problem.startswith(("added: ", "missing: ")):
        return problem.split(": ", 1)[1]
    return f"{prefix}/{_item(problem)}".rstrip("/")


def _shot_id(path: str):
    """The shot a root path names ("/shot_000002" -> 2), else None."""
    match = re.fullmatch(r"/shot_(\d+)", path)
    return int(match.group(1)) if match else None


def _shared_groups(f, bad, added=()) -> tuple:
    """({key: group} of the readable shared groups, {key: problems} of the damaged ones,
    {address: path} of every object in them); groups in ``added`` (root paths) are left out."""
    shared: dict = {}
    problems: dict[str, list] = {}
    linked: dict = {}
    try:
        keys = sorted(f["shared"]) if "shared" in f else []
    except Exception as exc:  # noqa: BLE001
        bad.append(_row(None, "/shared", f"unreadable ({_line(exc)})"))
        return shared, problems, linked
    for key in keys:
        if f"/shared/{key}" in added:
            continue
        try:
            group = f["shared"][key]
            found = named(damage(group, {}), f"/shared/{key}")
            linked.update(addresses(group))
            shared[key] = group
        except Exception as exc:  # noqa: BLE001
            found = [f"unreadable ({_line(exc)})"]
        if found:
            problems[key] = found
    return shared, problems, linked


def _item(problem: str) -> str:
    """The dataset or attribute a problem line names ("data/CH1", "data/CH1@units")."""
    head = problem.split(": ", 1)[0].removeprefix("attribute ")
    return "" if head.startswith("unreadable") else head


def addresses(group) -> dict:
    """{address: path} of ``group`` and every object below it."""
    out: dict = {}

    def visit(name, obj):
        out.setdefault(address(obj), obj.name)

    out[address(group)] = group.name
    group.visititems(visit)
    return out


def _row(shot, where, reason) -> dict:
    return {"shot": shot, "shots": [] if shot is None else [shot], "where": where, "reason": reason}


def _line(exc) -> str:
    return (str(exc).splitlines() or [type(exc).__name__])[0] or type(exc).__name__
