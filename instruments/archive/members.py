"""The root's member lists in the form a layout-3 or -4 master records them: its shots as
ranges of ids (``"shot_ids": [[1, 10000]]``), so that the attribute an append rewrites stays
small however many shots the archive holds."""
from __future__ import annotations

import re


def compact(members: dict) -> dict:
    """``members`` with the root's shot names as ranges of ids, ``"shot_ids": [[first, last],
    ...]`` (the form a master of layout 3 or 4 records)."""
    ids = [int(n[5:]) for n in members["/"] if re.fullmatch(r"shot_\d{6}", n)]
    return {**members, "/": [n for n in members["/"] if not re.fullmatch(r"shot_\d{6}", n)],
            "shot_ids": with_ids([], ids)}


def with_ids(ranges: list, ids) -> list:
    """The ranges of shot ids ``ranges`` ([[first, last], ...], sorted) with ``ids`` added."""
    out = [list(r) for r in ranges]
    for i in sorted(ids):
        if out and int(out[-1][1]) == i - 1:
            out[-1][1] = i
        else:
            out.append([i, i])
    return sorted(out)


def expanded(stored: dict) -> dict:
    """A recorded member list with its ranges of shot ids (``compact``) as names again."""
    if "shot_ids" not in stored:
        return stored
    names = [f"shot_{i:06d}" for first, last in stored["shot_ids"] for i in range(int(first), int(last) + 1)]
    return {**{k: v for k, v in stored.items() if k != "shot_ids"}, "/": sorted([*stored.get("/", []), *names])}
