"""Where an object of an archive file is, and its external links read without being followed.

An object's address, its file's absolute path and its address in that file, is the same
for every hard link to it, for the paths that reach it through HDF5 external links (the
part files of layouts 3 and 4) and for a part opened directly: the checksum tables
(digest.py) and the verify (verify.py) tell objects apart by it. An external link's row of
a table (``link:<path> in <file>``) is read from the link itself.
"""
from __future__ import annotations

import os

from .values import hdf5_id


def address(obj) -> tuple:
    """The object's (an h5py object or its HDF5 identifier) file (its absolute path) and
    address in it: equal for every hard link to it, for the paths that reach it through
    external links (the part files of layouts 3 and 4), and for a part opened directly
    (instruments/archive/links.py)."""
    import h5py

    oid = hdf5_id(obj)
    return os.path.abspath(h5py.h5f.get_name(oid).decode()), h5py.h5o.get_info(oid).addr


def member_address(group, name: str) -> tuple:
    """address() of ``group[name]``, a hard link, without opening the object."""
    import h5py

    return os.path.abspath(h5py.h5f.get_name(group.id).decode()), h5py.h5o.get_info(group.id, name.encode()).addr


def external(g, name: str) -> str | None:
    """The row of ``g[name]`` where it is an HDF5 external link ("link:/shared/k/x in
    part.h5"), else None; the link is not followed."""
    link = external_link(g, name)
    return external_row(link) if link is not None else None


def external_link(g, name: str):
    """``g[name]`` as an h5py.ExternalLink where it is one, else None (no such member, or
    another kind of link): as ``g.get(name, getlink=True)`` gives it, through HDF5's own
    calls (h5py's costs four times as much)."""
    import h5py

    try:
        info = g.id.links.get_info(name.encode())
    except KeyError:
        return None
    if info.type != h5py.h5l.TYPE_EXTERNAL:
        return None
    filename, path = (part.decode("utf8", "surrogateescape") for part in g.id.links.get_val(name.encode()))
    return h5py.ExternalLink(filename, path)


def external_row(link) -> str:
    """The row of an HDF5 external link (an h5py.ExternalLink)."""
    return f"link:{link.path} in {link.filename}"
