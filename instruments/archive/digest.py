"""The archive's checksum tables: a SHA-256 for every value a reader sees.

A group's table (``checksums``, a JSON text dataset in the group) has one row per item of
its tree, in sorted order: ``path`` -> the SHA-256 of a dataset's dtype, shape and values,
``path@name`` -> the SHA-256 of an attribute's value, ``path/`` -> that of a group's member
names. A hard link to an object that another table covers (the truth shared by the shots
of one scene) is a row ``link:<path>`` instead; an HDF5 external link (layout 3: a shot
whose scene was stored by an earlier transaction, in another part file) is the row
``link:<path> in <file>``, read from the link itself, never followed. Object references (the dimension scales of
xarray and netCDF) are hashed as the paths they point to. The group's attribute ``sha256``
is the SHA-256 of the table's text, so a damaged table is found too.

HDF5's own fletcher32 checks (every array dataset) raise while the values are read; each
such error is caught and its row says so ("unreadable: ..."). Comparing a table with the
file as it now reads: compare.py.
"""
from __future__ import annotations

import functools
import json
from dataclasses import dataclass
from typing import TYPE_CHECKING

from .addresses import address, external, member_address
from .hashes import attribute_digest, sha, value_digest
from .stored import TABLE
from .values import attribute_names, attribute_value, dataset_value, h5py_object, hdf5_id

if TYPE_CHECKING:
    import h5py

DIGEST = "sha256"  # the group attribute that holds the table's own SHA-256
_REFERENCE_ATTRS = ("DIMENSION_LIST", "REFERENCE_LIST")


def paths(group: h5py.Group, linked: dict) -> dict:
    """{address: path inside ``group``} of every object, the first path in sorted order;
    objects in ``linked`` (address -> the covering table's path) are not entered."""
    out = {address(group): "."}
    _enter(group, "", out, linked)
    return out


def _enter(g, prefix: str, out: dict, linked: dict):
    """paths(): the objects below ``g``, depth first in sorted order (a module function, not
    a closure: a recursive closure's cycle would keep the groups, and their part files, open)."""
    import h5py

    for name in sorted(g):
        if external(g, name):
            continue
        try:
            obj = g[name]
            a = address(obj)
        except Exception:  # noqa: BLE001 - table() reports it
            continue
        if a in out or a in linked:
            continue
        out[a] = prefix + name
        if isinstance(obj, h5py.Group):
            _enter(obj, prefix + name + "/", out, linked)


def table(group: h5py.Group, linked: dict, written: dict | None = None, hashed: dict | None = None) -> dict:
    """The rows of ``group``'s table as the file reads now. An item that cannot be read
    gets the row ``unreadable: <cause>`` (never an exception). ``written`` ({address: the
    value_digest of the values a writer has just given a dataset}, and {(address, name):
    the attribute_digest of an attribute's}) spares reading those back: the writer hashes
    what it wrote, in one pass. ``hashed`` (one check of many groups in the same open
    files: rig verify) keeps the rows of each dataset with more than one hard link (a
    part's time axis, shared by its shots of one time base) from the first group that
    reads it, for the others: its values and attributes read and hashed once, not once per
    shot."""
    rows: dict[str, str] = {}
    a = address(group)
    _walk(group, a, "", _Tree(group, {a: "."}, {}, linked, rows, written or {}, hashed))
    return rows


@dataclass(frozen=True)
class _Tree:
    """What table()'s walk reads and fills: the sealed group, {address: path} inside it of
    the objects met so far (the walk and paths() go in one order: the first path met is
    the first in sorted order), {address: path} of every object inside it and of the linked
    ones (filled by names(), for the dimension scales' references only), the linked
    objects, the rows, the digests of datasets just written (not read back), the rows of
    datasets with several hard links that an earlier group of the same check hashed
    (table's ``hashed``; None: none kept)."""

    group: object
    where: dict
    names: dict
    linked: dict
    rows: dict
    written: dict
    hashed: dict | None = None


def _attrs(obj, a, path: str, t: _Tree, into: dict | None = None):
    """The rows of ``obj``'s attributes (``path@name``), into ``t.rows`` (or ``into``)."""
    rows = t.rows if into is None else into
    for key in sorted(attribute_names(obj)):
        if obj is t.group and key in (DIGEST, TABLE):
            continue
        refs = names(t) if key in _REFERENCE_ATTRS else {}
        rows[f"{path}@{key}"] = t.written.get((a, key)) or _guard(functools.partial(_attr_digest, obj, key, refs))


def _dataset_rows(obj, a, path: str, t: _Tree):
    """A dataset's rows, its values' (``path``) and its attributes' (``path@name``), into
    ``t.rows``. Where ``t.hashed`` keeps rows and the dataset has more than one hard link,
    they are computed once per object of an open file (HDF5's file number and the object's
    address) and kept; rows of dimension-scale references (paths inside the sealed group)
    are not kept."""
    import h5py

    held = kept = None
    if t.hashed is not None:  # a dataset with several hard links: keyed by its file and address
        info = h5py.h5o.get_info(obj)
        held = (info.fileno, info.addr) if info.rc > 1 else None
        kept = t.hashed.get(held) if held is not None else None
    if kept is None:
        kept = {"": t.written.get(a) or _guard(functools.partial(_dataset_digest, obj))}
        _attrs(obj, a, "", t, kept)
        if t.hashed is not None and held is not None and not any(k[1:] in _REFERENCE_ATTRS for k in kept):
            t.hashed[held] = kept
    t.rows.update({path + k: row for k, row in kept.items()})


def names(t) -> dict:
    """``t.names`` ({address: path} of the whole group and of its linked objects), walked
    once, where a dimension scale's references are first met."""
    if not t.names:
        t.names.update({**paths(t.group, t.linked), **t.linked})
    return t.names


def _walk(g, a, prefix: str, t: _Tree):
    import h5py

    members = sorted(n for n in g if n != TABLE or g is not t.group)
    t.rows[prefix or "/"] = member_row(members)
    _attrs(g, a, prefix.rstrip("/"), t)
    for name in members:
        path = prefix + name
        link = external(g, name)
        if link:
            t.rows[path] = link
            continue
        try:
            obj = h5py.h5o.open(g.id, name.encode())  # as g[name] does, without its h5py object
            a = address(obj)
        except Exception as exc:  # noqa: BLE001 - a damaged link or header is a finding
            t.rows[path] = f"unreadable: {first_line(exc)}"
            continue
        if a in t.linked:
            t.rows[path] = "link:" + t.linked[a]
        elif a in t.where:
            t.rows[path] = "link:./" + t.where[a]
        elif isinstance(obj, h5py.h5g.GroupID):
            t.where[a] = path
            _walk(h5py.Group(obj), a, path + "/", t)
        else:
            t.where[a] = path
            _dataset_rows(obj, a, path, t)


def seal(group: h5py.Group, linked: dict, written: dict | None = None, attribute: bool = False):
    """Write ``group``'s table and its digest (after everything else in it is written;
    ``written``: as for table()); the table is a dataset, or with ``attribute`` (layout 4:
    one object fewer per shot) an attribute of the group."""
    seal_rows(group, table(group, linked, written), attribute)


def seal_rows(group: h5py.Group, rows: dict, attribute: bool = False) -> str:
    """Write ``rows`` as ``group``'s table, and its digest (seal, for a writer that has
    made every row of the group itself); returns the table's text as written."""
    text = json.dumps(rows, sort_keys=True, indent=0)
    if attribute:
        group.attrs[TABLE] = text
    else:
        group.create_dataset(TABLE, data=text)
    group.attrs[DIGEST] = sha(text.encode())
    return text


def member_row(names) -> str:
    """The row of a group's member names (``path/``; the sealed group's own table, a
    dataset, not among them)."""
    return sha(json.dumps(sorted(names)).encode())


def rows(group: h5py.Group, keys: list, linked: dict, stored: dict, known: dict | None = None) -> dict:
    """The rows ``keys`` of ``group``'s table as the file reads now, each computed alone (no
    walk over the rest of the group), and those of ``known`` (rows a reader computed) that the
    table holds; ``stored``: the table as sealed, which says where a row is a hard link
    inside the group (only then is the group walked for its paths)."""
    import h5py

    t, objects = _Tree(group, {}, {}, linked, {}, {}), {"": group}

    def at(path: str):  # each object looked up once (a path lookup costs as much as a small read)
        if path not in objects:  # opened as group[path] does, without its h5py object for a dataset
            oid = h5py.h5o.open(group.id, path.encode())
            objects[path] = h5py.Group(oid) if isinstance(oid, h5py.h5g.GroupID) else oid
        return objects[path]

    out = {k: v for k, v in (known or {}).items() if k in stored}
    for key in keys:
        try:
            out[key] = _row(at, key, stored.get(key, ""), t)
        except Exception as exc:  # noqa: BLE001 - damage is reported, never raised
            out[key] = f"unreadable: {first_line(exc)}"
    return out


def _row(at, key: str, sealed: str, t: _Tree) -> str:
    """One row of table() (see _walk), computed alone; ``at(path)``: the object at a path
    inside the group ("": the group); ``sealed``: the row as stored."""
    path, is_attr, attr = key.partition("@")
    path = path.strip("/")
    if not is_attr and not key.endswith("/"):  # a dataset or a link: an external link is not followed
        parent, _, name = path.rpartition("/")
        link = external(at(parent), name)
        if link:
            return link
        a = member_address(at(parent), name)  # a link to what another table covers: not opened
        if a in t.linked:
            return "link:" + t.linked[a]
        if sealed.startswith("link:./"):
            return "link:./" + names(t).get(a, "?") if names(t).get(a) != path else "not a link"
        return _dataset_digest(at(path))
    obj, group = at(path), at("")
    if is_attr:
        return _attr_digest(obj, attr, names(t) if attr in _REFERENCE_ATTRS else {})
    return member_row(n for n in h5py_object(obj) if n != TABLE or obj is not group)  # a group's member names


def _dataset_digest(d) -> str:
    return value_digest(dataset_value(hdf5_id(d)))  # fletcher32 is checked chunk by chunk here


def _attr_digest(obj, key, names) -> str:
    if key in _REFERENCE_ATTRS:
        return sha(json.dumps(_references(h5py_object(obj), key, names)).encode())
    return attribute_digest(attribute_value(obj, key))


def _references(obj, key, names) -> list:
    """The paths the references of a dimension-scale attribute point to."""
    f = obj.file
    if key == "DIMENSION_LIST":
        return [[names.get(address(f[r]), "?") for r in row] for row in obj.attrs[key]]
    return [[names.get(address(f[row[0]]), "?"), int(row[1])] for row in obj.attrs[key]]


def _guard(compute) -> str:
    try:
        return compute()
    except Exception as exc:  # noqa: BLE001 - damage is reported, never raised
        return f"unreadable: {first_line(exc)}"


def first_line(exc) -> str:
    """An exception's first line of text (its type's name where it has none)."""
    return (str(exc).splitlines() or [type(exc).__name__])[0] or type(exc).__name__
