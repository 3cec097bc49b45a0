"""HDF5 shot archive (NeXus-style) that never loses a committed shot.

The layout of one shot: instruments/archive_layout.py.

Appends are transactions. Under an exclusive lock (``ARCHIVE.h5.lock``) the archive is
copied to a temporary file beside it, the new shots are written there, the copy is flushed
to disk (fsync), and ``os.replace`` puts it in place atomically; then the directory is
synced. A writer killed at any moment, a power loss or a full disk leaves either the old
archive or the new one, never a mix, and a stale temporary file is removed by the next
append. Readers open the path and see one complete version: this is what SWMR would give,
without SWMR's ban on creating groups. The price is a file copy per transaction; append
many shots in one call where that matters.
"""
from __future__ import annotations

import contextlib
import fcntl
import json
import os
import shutil
import tempfile
from pathlib import Path
from typing import TYPE_CHECKING

from .archive_layout import LAYOUT, Entry, raw_digest, read_entry, write_entry
from .errors import InstrumentError

if TYPE_CHECKING:  # h5py itself is imported where a file is opened
    import h5py

__all__ = ["Archive", "Entry", "raw_digest"]

class Archive:
    """A shot archive at ``path`` (created on the first append)."""

    def __init__(self, path):
        self.path = Path(path)

    # --- writing --------------------------------------------------------------------
    def append(self, entries) -> list:
        """Append shots in one transaction; returns their ids. All or nothing."""
        import h5py

        entries = list(entries)
        with self._lock():
            self._drop_stale_temporaries()
            fd, tmp = tempfile.mkstemp(prefix=f".{self.path.name}.", suffix=".tmp", dir=self.path.parent)
            os.close(fd)
            try:
                if self.path.exists():
                    self._open(self.path).close()  # refuse to build on a broken archive
                    shutil.copyfile(self.path, tmp)
                    shutil.copymode(self.path, tmp)
                else:
                    umask = os.umask(0)
                    os.umask(umask)
                    os.chmod(tmp, 0o666 & ~umask)
                with h5py.File(tmp, "a", libver=("v110", "latest")) as f:
                    if "NX_class" not in f.attrs:
                        f.attrs.update({"NX_class": "NXroot", "creator": "sonic-rig", "layout": LAYOUT})
                    start = max([_shot_id(n) for n in f if n.startswith("shot_")] + [0]) + 1
                    ids = [start + i for i in range(len(entries))]
                    checked = set()
                    for shot_id, e in zip(ids, entries):
                        write_entry(f, shot_id, e, checked)
                    f.attrs["default"] = f"shot_{ids[-1]:06d}" if ids else f.attrs.get("default", "")
                _fsync(tmp)
                os.replace(tmp, self.path)
                _fsync_dir(self.path.parent)
            except BaseException:
                with contextlib.suppress(OSError):
                    os.unlink(tmp)
                raise
        return ids

    @contextlib.contextmanager
    def _lock(self):
        self.path.parent.mkdir(parents=True, exist_ok=True)
        with open(self.path.with_name(self.path.name + ".lock"), "a") as fh:
            fcntl.flock(fh, fcntl.LOCK_EX)
            try:
                yield
            finally:
                fcntl.flock(fh, fcntl.LOCK_UN)

    def _drop_stale_temporaries(self):
        for stale in self.path.parent.glob(f".{self.path.name}.*.tmp"):
            with contextlib.suppress(OSError):
                stale.unlink()  # we hold the lock: no live writer owns it

    # --- reading --------------------------------------------------------------------
    def _open(self, path=None) -> h5py.File:
        import h5py

        path = Path(path or self.path)
        if not path.exists():
            raise InstrumentError(f"{path}: no such archive")
        if not h5py.is_hdf5(path):
            raise InstrumentError(f"{path}: not an HDF5 file")
        try:
            f = h5py.File(path, "r")
        except OSError as exc:
            raise InstrumentError(f"{path}: cannot be opened as HDF5 (truncated or damaged?): {exc}") from None
        if f.attrs.get("creator") != "sonic-rig":
            f.close()
            raise InstrumentError(f"{path}: not a rig archive (an HDF5 file that this project did not write)")
        return f

    def ids(self) -> list:
        with self._open() as f:
            return sorted(_shot_id(n) for n in f if n.startswith("shot_"))

    def read(self, shot_id: int, verify: bool = True, with_truth: bool = True) -> Entry:
        """The stored shot as the same record objects the scope produces."""
        with self._open() as f:
            name = f"shot_{shot_id:06d}"
            if name not in f:
                raise InstrumentError(f"{self.path}: no shot {shot_id} (shots: {_id_range(f)})")
            return read_entry(f[name], verify, self.path, with_truth)

    def verify(self) -> dict:
        """Check every shot (fletcher32 on every chunk, then the sha256)."""
        import h5py

        try:
            f = self._open()
        except InstrumentError as exc:
            return {"shots": 0, "ok": 0, "bad": [{"shot": None, "reason": str(exc)}]}
        bad, n = [], 0
        with f:
            checked = set()  # shared datasets (hard links) are read once
            for name in sorted(k for k in f if k.startswith("shot_")):
                n += 1
                try:
                    read_entry(f[name], True, self.path, with_truth=False)
                    for obj in _datasets(f[name]):
                        info = h5py.h5o.get_info(obj.id)
                        key = info.token if hasattr(info, "token") else info.addr
                        if key not in checked:
                            obj[()]  # fletcher32 is checked chunk by chunk as it is read
                            checked.add(key)
                except (OSError, InstrumentError, KeyError, ValueError) as exc:
                    bad.append({"shot": _shot_id(name), "reason": str(exc).splitlines()[0]})
        return {"shots": n, "ok": n - len(bad), "bad": bad}

    def digests(self) -> dict:
        """{shot id: the SHA-256 of its raw data}, as stored (no shot read)."""
        with self._open() as f:
            return {_shot_id(n): f[n].attrs["shot"]["sha256"].decode() for n in f if n.startswith("shot_")}

    def summary(self) -> list:
        """One row per shot: id, time, simulated, scene, seed, channels, triggered."""
        rows = []
        with self._open() as f:
            for name in sorted(k for k in f if k.startswith("shot_")):
                g = f[name]
                a = g.attrs["shot"]
                settings = json.loads(g["settings"][()])
                rows.append({"shot": int(a["shot_id"]), "start_time": a["start_time"].decode(),
                             "simulated": bool(a["simulated"]), "scene": a["scene"].decode(),
                             "seed": int(a["seed"]) if a["seed"] >= 0 else None,
                             "triggered": bool(a["triggered"]),
                             "channels": sorted(g["instrument/oscilloscope"]),
                             "sources": settings.get("source_files", []),
                             "settings": settings.get("striker", {})})
        return rows


def _datasets(group):
    import h5py

    out = []
    group.visititems(lambda name, obj: out.append(obj) if isinstance(obj, h5py.Dataset) else None)
    return out


def _shot_id(name: str) -> int:
    return int(name.split("_", 1)[1])


def _id_range(f) -> str:
    ids = sorted(_shot_id(n) for n in f if n.startswith("shot_"))
    return f"{ids[0]}..{ids[-1]}" if ids else "none"


def _fsync(path):
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def _fsync_dir(path):
    with contextlib.suppress(OSError):
        _fsync(path)
