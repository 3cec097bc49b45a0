"""Opening an archive for reading, and the few reads every layout answers alike: which
layout a file is, a shot's stored SHA-256 of its raw data, the range of its shot ids."""
from __future__ import annotations

import json
import os
from pathlib import Path
from typing import TYPE_CHECKING

from ..errors import InstrumentError
from ..files import cause
from .compact import LAYOUT4
from .layout import LAYOUT_VERSION
from .parts import LAYOUT3
from .values import attribute_or
from .verify import shot_names

if TYPE_CHECKING:  # h5py itself is imported where a file is opened
    import h5py

READ = (LAYOUT_VERSION, LAYOUT3, LAYOUT4)  # the layouts read without `rig upgrade`


def open_archive(path, current: bool = True) -> h5py.File:
    """The archive at ``path`` opened for reading; one InstrumentError if it is missing, not
    HDF5, damaged, foreign, or (``current``) of a layout this version reads only to convert."""
    import h5py

    path = Path(path)
    if not path.exists():
        raise InstrumentError(f"{path}: no such archive")
    check_archive_path(path)
    if not h5py.is_hdf5(path):
        raise InstrumentError(f"{path}: not an HDF5 file")
    try:
        f = h5py.File(path, "r")
        creator, version = attribute_or(f, "creator"), attribute_or(f, "layout_version")
    except Exception as exc:  # noqa: BLE001 - any failure of a damaged file
        raise InstrumentError(f"{path}: cannot be opened as HDF5 (truncated or damaged?): {cause(exc)}") from None
    if creator != "sonic-rig":
        study = "study" in f.attrs and "outputs" in f  # a Monte Carlo study's results (rig mc)
        f.close()
        if study:
            raise InstrumentError(f"{path}: a Monte Carlo study's results (rig mc), not a shot archive: its "
                                  f"shots' scope records are archived under traces/ when it runs with --traces")
        raise InstrumentError(f"{path}: not a rig archive (an HDF5 file that this project did not write)")
    if current and version not in READ:
        f.close()
        raise InstrumentError(f"{path}: archive layout {version or 1}, this version reads layouts "
                              f"{', '.join(map(str, READ[:-1]))} and {READ[-1]}: "
                              f"run `rig upgrade {path}` to convert it")
    return f


def check_archive_path(path):
    """InstrumentError where ``path`` cannot be an archive file because it is a directory
    (HDF5 would say only that it is not an HDF5 file)."""
    if Path(path).is_dir():
        raise InstrumentError(f"{path}: is a directory; an archive is a file, e.g. "
                              f"{os.path.join(os.path.normpath(path), 'shots.h5')}")


def stored_raw_digest(g) -> str:
    """The stored SHA-256 of a shot's raw data (in its entry's metadata in layout 4, a
    dataset before)."""
    if "metadata" in g.attrs:
        return json.loads(g.attrs["metadata"])["raw_sha256"]
    value = g["raw_sha256"][()]
    return value.decode() if isinstance(value, bytes) else str(value)


def id_range(f) -> str:
    """"first..last" of the shot ids the root holds ("none" where it holds none)."""
    ids = [int(n.split("_", 1)[1]) for n in shot_names(f)]
    return f"{ids[0]}..{ids[-1]}" if ids else "none"
