"""Layouts 3 and 4: an archive is a small master file and a folder of part files, one per
transaction, that the master links to with HDF5 external links.

``shots.h5`` (the master) holds the root's attributes (layout, member lists, the root's
table of checksums) and one external link per shot (``/shot_000042`` ->
``shots.h5.d/shots_000040.h5:/shot_000042``) and per shared group (``/shared/scene_x`` ->
the part that stored it first). ``shots.h5.d/shots_NNNNNN.h5`` (a part, named by the first
shot it holds) is an HDF5 file of the transaction's NXentry groups (layout 3: layout 2's
groups; layout 4: instruments/archive/compact.py) and the shared groups of scenes new to the
archive; a shot of a scene stored by an earlier part
links to that part's shared group with external links. A part is written once, whole, and
never changed. h5py, h5netcdf (xarray) and nexusformat follow the links, relative to the
folder of the file that holds them; copying an archive means copying the master and its
folder, side by side.
"""
from __future__ import annotations

from pathlib import Path

from .members import compact, with_ids
from .verify import member_list

LAYOUT3 = 3
PARTS_TEXT = """Layout version {version}: this file is the master of the archive; each shot_NNNNNN and
each shared/<key> is an HDF5 external link into a part file in the folder <this file's
name>.d beside it (one part per transaction, written once, never changed); the groups they
link to are of layout {groups}, described below. Copy the file and its folder together."""


def folder(master: Path) -> Path:
    """The folder of ``master``'s part files: ``shots.h5`` -> ``shots.h5.d``."""
    return master.with_name(master.name + ".d")


def part_name(first_id: int) -> str:
    """The part file of a transaction whose first shot is ``first_id``."""
    return f"shots_{first_id:06d}.h5"


def link_into(master_name: str, part: str, path: str):
    """The external link, as the master stores it, to ``path`` in ``part``."""
    import h5py

    return h5py.ExternalLink(f"{master_name}.d/{part}", path)


def stored_shared(f) -> dict:
    """{key: (part file name, group)} of the shared groups a layout-3 master links to."""
    import h5py

    out = {}
    if "shared" in f:
        for key in f["shared"]:
            link = f["shared"].get(key, getlink=True)
            if isinstance(link, h5py.ExternalLink):
                out[key] = (Path(link.filename).name, f["shared"][key])
    return out


def recorded_ranges(f) -> dict:
    """The root's member lists as its sealed attribute records them, shots as ranges of ids
    ({"/": other names, "/shared": names, "shot_ids": [[first, last], ...]}; the walk over the
    root where the attribute is missing or unreadable): a large master's shots are read as a
    few numbers, never as one name each."""
    try:
        members = member_list(f, expand=False)
        if members is None:  # a version-1 root table: no list recorded
            raise ValueError("no member list")
        out = {"/": list(members["/"]), "/shared": list(members.get("/shared", []))}
        return compact(out) if "shot_ids" not in members else {**out, "shot_ids": members["shot_ids"]}
    except Exception:  # noqa: BLE001 - a damaged list: the writer builds on what the root holds
        return compact({"/": sorted(f), "/shared": sorted(f["shared"]) if "shared" in f else []})


def next_id(members: dict) -> int:
    """The id of the next shot after those ``members`` (recorded_ranges) lists."""
    return max([int(last) for _, last in members["shot_ids"]] + [0]) + 1


def add_shots(members: dict, ids: list, shared: list) -> dict:
    """``members`` (recorded_ranges) with the shots ``ids`` and the shared groups ``shared``
    a transaction adds (``/shared`` listed once it exists)."""
    ranges = with_ids(members["shot_ids"], ids)
    names = sorted({*members["/"], *(["shared"] if shared or members["/shared"] else [])})
    out = {"/": names, "shot_ids": ranges}
    if "shared" in names:
        out["/shared"] = sorted({*members["/shared"], *shared})
    return out
