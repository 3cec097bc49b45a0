"""Checking an open archive: the root's attributes, each shared group once, then each shot,
against their tables of SHA-256 checksums (instruments/archive_digest.py). Every problem is
a row naming the shot (or the shots of a shared group) and the dataset or attribute; a
damaged file gives rows, never an exception."""
from __future__ import annotations

import json
from typing import TYPE_CHECKING

from .archive_digest import address, damage, linked_groups, sha

if TYPE_CHECKING:
    import h5py

ROOT_TABLE = "checksums"  # root attribute: {attribute: SHA-256} of the root's other attributes


def root_seal(f: h5py.File):
    """Write the root's table (after its other attributes)."""
    f.attrs[ROOT_TABLE] = json.dumps(_root_rows(f), sort_keys=True)


def root_damage(f: h5py.File) -> list:
    try:
        stored = json.loads(f.attrs[ROOT_TABLE])
        now = _root_rows(f)
    except Exception as exc:  # noqa: BLE001
        return [f"attribute @{ROOT_TABLE}: unreadable ({_line(exc)})"]
    return [f"attribute @{k}: damaged" for k in sorted(set(stored) | set(now)) if stored.get(k) != now.get(k)]


def _root_rows(f) -> dict:
    out = {}
    for k in sorted(f.attrs):
        if k != ROOT_TABLE:
            v = f.attrs[k]
            out[k] = sha(repr(v.tolist() if hasattr(v, "tolist") else v).encode())
    return out


def shot_names(f: h5py.File) -> list:
    return sorted(k for k in f if k.startswith("shot_"))


def check(f: h5py.File) -> dict:
    """{"shots", "ok", "bad"}: bad rows {"shot", "shots", "where", "reason"}."""
    bad = [_row(None, "/" + _item(r), r) for r in root_damage(f)]
    try:
        names = shot_names(f)
    except Exception as exc:  # noqa: BLE001
        return {"shots": 0, "ok": 0, "bad": bad + [_row(None, "/", f"the root group is unreadable ({_line(exc)})")]}
    shared, problems, linked = _shared_groups(f, bad)
    users, shot_bad = {}, set()
    for name in names:
        shot_id = int(name.split("_", 1)[1])
        try:
            g = f[name]
            found = damage(g, linked)
            for key in linked_groups(g, "/shared/"):
                users.setdefault(key, []).append(shot_id)
        except Exception as exc:  # noqa: BLE001
            found = [f"unreadable ({_line(exc)})"]
        for p in found:
            bad.append(_row(shot_id, f"/{name}/{_item(p)}".rstrip("/"), p))
            shot_bad.add(shot_id)
    for key, found in problems.items():
        ids = sorted(users.get(key, []))
        shot_bad.update(ids)
        for p in found:
            bad.append({"shot": None, "shots": ids, "where": f"/shared/{key}/{_item(p)}".rstrip("/"),
                        "reason": f"{p} (shared by shot{'' if len(ids) == 1 else 's'} {', '.join(map(str, ids)) or '-'})"})
    return {"shots": len(names), "ok": len(names) - len(shot_bad), "bad": bad}


def _shared_groups(f, bad) -> tuple:
    """({key: group} of the readable shared groups, {key: problems} of the damaged ones,
    {address: path} of every object in them)."""
    shared, problems, linked = {}, {}, {}
    try:
        keys = sorted(f["shared"]) if "shared" in f else []
    except Exception as exc:  # noqa: BLE001
        bad.append(_row(None, "/shared", f"unreadable ({_line(exc)})"))
        return shared, problems, linked
    for key in keys:
        try:
            group = f["shared"][key]
            found = damage(group, {})
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
    out = {}

    def visit(name, obj):
        out.setdefault(address(obj), obj.name)

    out[address(group)] = group.name
    group.visititems(visit)
    return out


def _row(shot, where, reason) -> dict:
    return {"shot": shot, "shots": [] if shot is None else [shot], "where": where, "reason": reason}


def _line(exc) -> str:
    return (str(exc).splitlines() or [type(exc).__name__])[0] or type(exc).__name__
