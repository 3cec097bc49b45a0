"""Following a master's external links (layouts 3 and 4) the short way: the part a shot's
link names opened directly, the last part kept open for the next shot of the same part, so
that reading shot after shot (verify, summary) opens each part once and a read of one shot
does not go through HDF5's external-link traversal; and which rows of a shot's table a read
returns, by layout."""
from __future__ import annotations

import os

from .compact import LAYOUT4


class OpenParts:
    """The part file last opened directly; a context manager that closes it."""

    def __init__(self):
        self.path, self.file = None, None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def close(self):
        if self.file is not None:
            self.file.close()
        self.path, self.file = None, None

    def group(self, f, name: str):
        """The group ``f[name]``: where ``name`` is an external link, read from its part
        opened directly (KeyError where ``f`` has no such member; OSError where the part is
        missing or not HDF5)."""
        import h5py

        link = f.get(name, getlink=True)
        if link is None:
            raise KeyError(name)
        if not isinstance(link, h5py.ExternalLink):
            return f[name]
        path = os.path.join(os.path.dirname(f.filename), link.filename)
        if path != self.path or self.file is None:  # (a path is kept with its open file)
            self.close()
            self.file, self.path = h5py.File(path, "r"), path
        return self.file[link.path]


def returned_by_read(g):
    """Whether a row of the shot ``g``'s table is of what a read returns (a test of the
    row's key): in layout 4 not the time axes and the attributes of the NXdata plot and its
    datasets (NeXus and CF), which a read computes from the preambles (in ``@metadata``); in
    layouts 2 and 3, nothing of the plot (``data/``: volts and time
    computed from the codes and preambles, which lie in instrument/)."""
    if g.file.attrs.get("layout_version") == LAYOUT4:
        return lambda key: not key.startswith(("data/time", "data@")) and not (key.startswith("data/") and "@" in key)
    return lambda key: not key.startswith(("data/", "data@"))


def truth_item(problem: str) -> bool:
    """Whether a line of digest.damage names the truth's forces (the "forces" group,
    its datasets or attributes) of a shared group: what a read without the truth skips."""
    key = problem.removeprefix("attribute ").split(":", 1)[0]
    return key.split("@", 1)[0].split("/", 1)[0] == "forces"
