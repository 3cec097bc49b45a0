"""Following a master's external links (layouts 3 and 4) the short way: the part a shot's
link names opened directly and kept open, so that reading shot after shot (verify, summary)
opens each part once, a read of one shot does not go through HDF5's external-link
traversal, and an Archive's reads find the parts they read last open, their HDF5 metadata
already read (a part is written once and never changed: one whose file was replaced or
removed since is opened again); and which rows of a shot's table a read returns, by layout."""
from __future__ import annotations

import os

from .addresses import external_link
from .compact import LAYOUT4


def file_identity(path) -> tuple | None:
    """What tells one version of the file at ``path`` from another (inode, size,
    modification time); None where there is no file."""
    try:
        st = os.stat(path)
    except OSError:
        return None
    return st.st_ino, st.st_size, st.st_mtime_ns


class OpenParts:
    """The part files opened directly (or an archive's master, Archive: one kept): the
    ``kept`` last used, each with the identity of the file it was opened from; a context
    manager that closes them."""

    def __init__(self, kept: int = 1):
        self.kept = kept
        self.files: dict = {}  # {path: (file_identity, h5py.File)}, the last used last

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def close(self):
        for _, file in self.files.values():
            file.close()
        self.files = {}

    def group(self, f, name: str):
        """The group ``f[name]`` (``f``: a file or a group): where ``name`` is an external
        link, read from its part opened directly (KeyError where ``f`` has no such member;
        OSError where the part is missing or not HDF5)."""
        link = external_link(f, name)
        if link is None:
            return f[name]
        return self.file(os.path.join(os.path.dirname(f.file.filename), link.filename))[link.path]

    def file(self, path: str, opener=None):
        """The part at ``path``, open (opened again where the file there is not the one it
        was opened from); ``opener(path)`` opens it (default: h5py, read-only)."""
        import h5py

        identity = file_identity(path)
        held = self.files.pop(path, None)
        if held is not None and (identity is None or held[0] != identity):
            held[1].close()
            held = None
        if held is None:
            held = identity, (opener or (lambda p: h5py.File(p, "r")))(path)
        self.files[path] = held
        while len(self.files) > self.kept:
            self.files.pop(next(iter(self.files)))[1].close()
        return held[1]


def returned_by_read(layout):
    """Whether a row of a shot's table is of what a read returns (a test of the row's key),
    for a shot of ``layout`` (the layout_version of the file that holds it): in layout 4 not
    the time axes and the attributes of the NXdata plot and its datasets (NeXus and CF),
    which a read computes from the preambles (in ``@metadata``); in layouts 2 and 3, nothing
    of the plot (``data/``: volts and time computed from the codes and preambles, which lie
    in instrument/)."""
    if layout == LAYOUT4:
        return lambda key: not key.startswith(("data/time", "data@")) and not (key.startswith("data/") and "@" in key)
    return lambda key: not key.startswith(("data/", "data@"))


def truth_item(problem: str) -> bool:
    """Whether a line of compare.damage names the truth's forces (the "forces" group,
    its datasets or attributes) of a shared group: what a read without the truth skips."""
    key = problem.removeprefix("attribute ").split(":", 1)[0]
    return key.split("@", 1)[0].split("/", 1)[0] == "forces"
