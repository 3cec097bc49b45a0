"""The archives of ``rig bench archive``'s rows at 10,000 and 100,000 shots, written
directly rather than appended: one small shot (one channel of 16 codes, an imported file's
form) appended through the Archive, then parts of 1,000 shots each made of copies of it
(HDF5's own object copy, table of checksums included: a shot's table names nothing outside
it), then the master's links to them and its root sealed as a transaction would seal it.
The result is an archive of layout 4 that verifies; building it takes seconds where
appending 100,000 shots would take many minutes, and a one-shot append or a read costs the
same on it as on an archive grown by appends of the same parts."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from instruments.archive import Archive, Entry
from instruments.archive.parts import folder, link_into, part_name
from instruments.archive.verify import root_seal
from instruments.records import Preamble, ScopeRecord, Waveform

PER_PART = 1000


def small_shot(seed: int) -> Entry:
    """A real shot of one channel of 16 int8 codes."""
    p = Preamble(points=16, x_increment=1e-6, x_zero=0.0, trigger_index=0, y_multiplier=0.01, y_offset=0.0,
                 y_zero=0.0)
    codes = np.random.default_rng(seed).integers(-100, 100, 16).astype(np.int8)
    return Entry(ScopeRecord({"CH1": Waveform("CH1", p, codes=codes)}, True), False,
                 settings={"source_files": [f"s{seed}.isf"]}, start_time="2026-01-01T00:00:00+00:00")


def build(path: Path, n: int) -> Archive:
    """An archive at ``path`` of ``n`` small shots, its parts written directly (see above)."""
    import h5py

    archive = Archive(path)
    archive.append([small_shot(0)])
    where = folder(path)
    with h5py.File(where / part_name(1), "r") as template:
        shot = template["shot_000001"]
        for first in range(2, n + 1, PER_PART):
            with h5py.File(where / part_name(first), "w", libver=("v110", "latest")) as part:
                part.attrs.update(template.attrs)
                for i in range(first, min(first + PER_PART, n + 1)):
                    template.copy(shot, part, f"shot_{i:06d}")
    with h5py.File(path, "a") as master:
        for first in range(2, n + 1, PER_PART):
            for i in range(first, min(first + PER_PART, n + 1)):
                master[f"shot_{i:06d}"] = link_into(path.name, part_name(first), f"/shot_{i:06d}")
        master.attrs["default"] = f"shot_{n:06d}"
        root_seal(master, {"/": [], "shot_ids": [[1, n]]})
    return archive
