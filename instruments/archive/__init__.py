"""HDF5 shot archive (NeXus) that never loses a committed shot, whose appends cost what
they add.

Layout 4 (instruments/archive/compact.py, the layout of a new archive): a small master file
(``shots.h5``) whose shots and shared groups are HDF5 external links into part files
(``shots.h5.d/shots_NNNNNN.h5``), one per transaction, written once and never changed
(instruments/archive/parts.py, commit.py); a shot in a part is a handful of HDF5 objects: its
raw codes once, read as volts through CF packing attributes, its scalars as attributes, one
table of checksums (digest.py, verify.py). Layout 3 (the same master and parts, each shot
in layout 2's groups, instruments/archive/layout.py) is read and still appended to in layout
3; layout 2 (one file) is read and still appended to in layout 2, by a copy of the whole
file per transaction; ``rig upgrade`` (``Archive.upgrade``) converts layouts 1 (through
legacy.py), 2 and 3 to layout 4; layout 1 is refused with a line that says so.

Appends are transactions under an exclusive lock (``ARCHIVE.h5.lock``). The new shots are
written into a new part: its image is built in memory (HDF5 writes no file itself: an HDF5
write that fails on a full disk leaves the library in a state that can crash the process),
written to a temporary file, flushed to disk (fsync) and renamed into place; then the master
is copied, the links to the new part added, its root sealed, and the copy flushed and put in
place with ``os.replace``; each rename is followed by a sync of its folder. Nothing already
stored is copied: the master holds links only. A writer killed at any moment, a power loss
or a full disk leaves either the old master or the new one, each naming only whole parts; a
part no master names (a writer killed between the two renames) is replaced by the next
transaction of the same first shot, and a stale temporary file is removed by the next
append. Readers open the master and see one complete version: this is what SWMR would give,
without SWMR's ban on creating groups. A read goes from the master's link straight to the
part that holds the shot; an Archive keeps the master and the parts it read last open for
its next read, and opens again a master or part whose file was replaced or removed since
(instruments/archive/links.py). An I/O failure (a full disk, no permission) or a damaged archive
ends an append with one InstrumentError naming the archive and the cause; the archive is
left as it was.
"""
from __future__ import annotations

import contextlib
import numbers
import os
import shutil
import tempfile
import threading
from pathlib import Path
from typing import TYPE_CHECKING

from ..errors import InstrumentError
from ..files import cause, folder_lock, hdf5_image
from ..files import fsync as _fsync  # a name of this module's own: the crash tests stop a writer after it
from .commit import commit_parts
from .compact import LAYOUT4, LAYOUT4_TEXT
from .entry import Entry, raw_digest
from .layout import LAYOUT as LAYOUT2_TEXT
from .layout import LAYOUT_VERSION, write_entry
from .links import OpenParts
from .opening import check_archive_path, id_range, open_archive, stored_raw_digest
from .parts import LAYOUT3, folder
from .reader import checked_shot, read_entry, read_shot, summary_row
from .shared import SharedGroups
from .values import attribute_or
from .verify import check, root_seal, sealed_members, shot_names

if TYPE_CHECKING:  # h5py itself is imported where a file is opened
    import h5py

__all__ = ["Archive", "Entry", "check_archive_path", "raw_digest", "stored_raw_digest"]
LAYOUT, CURRENT_LAYOUT = LAYOUT4_TEXT, LAYOUT4  # what a new archive is written in
PARTS_KEPT = 4  # the part files an Archive keeps open between reads (a shot's part, its scene's, ...)


class Archive:
    """A shot archive at ``path`` (created on the first append)."""

    def __init__(self, path):
        self.path = Path(path)
        self._shared = SharedGroups()  # the shared groups found intact, by version of their file (shared.py)
        self._master = OpenParts(kept=1)  # the master open for reading, while it is the file at its path
        self._parts = OpenParts(kept=PARTS_KEPT)  # the parts read last, kept open
        self._reading = threading.Lock()  # one read at a time uses them

    def close(self) -> None:
        """Close the files kept open for reads (the master and the parts read last); the
        next read opens them again. ``with Archive(path) as a:`` closes them at the end."""
        with self._reading:
            self._master.close()
            self._parts.close()

    def __enter__(self) -> Archive:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    # --- writing --------------------------------------------------------------------
    def append(self, entries) -> list:
        """Append shots in one transaction; returns their ids. All or nothing. An archive of
        layout 2 grows in layout 2 (a copy per transaction), one of layout 3 in layout 3,
        until ``rig upgrade``."""
        entries = list(entries)
        with self._lock():
            self._drop_stale_temporaries()
            if not self.path.exists():
                return commit_parts(self.path, entries, self._transaction)
            master = self._open()
            if master.attrs.get("layout_version") == LAYOUT_VERSION:
                master.close()
                return self._transaction(lambda f: self._write(f, entries), True)
            return commit_parts(self.path, entries, self._transaction, master)

    def upgrade(self) -> int:
        """Rewrite an archive of layout 1, 2 or 3 in layout 4 (one transaction); returns the
        number of shots. An archive of layout 4 is left as it is (0); one of layout 2 or 3
        that does not verify is refused (InstrumentError): converting it would accept its
        damage. The parts of layout 3 that the new master no longer names are removed."""
        from .legacy import read_legacy_entry

        with self._lock():
            with self._open(current=False) as f:
                version = f.attrs.get("layout_version")
                if version == LAYOUT4:
                    return 0
                bad = check(f)["bad"] if version in (LAYOUT_VERSION, LAYOUT3) else []
                if bad:
                    raise InstrumentError(f"{self.path}: {len(bad)} problem{'' if len(bad) == 1 else 's'} (first: "
                                          f"{bad[0]['where']}: {bad[0]['reason']}); `rig verify` lists them; an "
                                          "archive is converted only when it verifies")
                read = read_entry if version in (LAYOUT_VERSION, LAYOUT3) else read_legacy_entry
                entries = [read(f[n], self.path, keyed=True) if read is read_entry else read(f[n], self.path)
                           for n in shot_names(f)]
            self._drop_stale_temporaries(every=True)
            old = sorted(folder(self.path).glob("*.h5"))  # layout 3's parts, removed once no master names them
            ids = [e.shot_id for e in entries]
            part = f"upgraded_{ids[0] if ids else 0:06d}.h5"
            count = len(commit_parts(self.path, entries, self._transaction, ids=ids, part=part))
            for stale in old:
                if stale.name != part:
                    stale.unlink()
            return count

    def lists_members(self) -> bool:
        """Whether the root records its member lists (instruments/archive/verify.py): False
        for layout 1 and for a layout-2 archive sealed before they were."""
        with self._open(current=False) as f:
            return sealed_members(f)
    def _transaction(self, write, copy: bool, target=None) -> list:
        """Write into a copy of ``target`` (the archive's file) or a new file, then put it in
        place: whole or not at all. A part's temporary file has its part's name
        (``.shots_NNNNNN.h5.tmp``): a writer killed before its rename left it under the name
        the next transaction, of the same first shot, writes again, so no append lists the
        folder of parts to find stale ones."""
        target = Path(target or self.path)
        if target == self.path:
            fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".tmp", dir=target.parent)
        else:
            tmp = str(target.with_name(f".{target.name}.tmp"))
            fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
        os.close(fd)
        try:
            if copy:
                self._open().close()  # refuse to build on a broken or foreign archive
                shutil.copyfile(target, tmp)
                shutil.copymode(target, tmp)
            else:
                umask = os.umask(0)
                os.umask(umask)
                os.chmod(tmp, (os.stat(self.path).st_mode if self.path.exists() else 0o666 & ~umask) & 0o7777)
            image = Path(tmp).read_bytes() if copy else None
            data, ids = hdf5_image(write, image, libver=("v110", "latest"))  # HDF5 itself writes no file
            Path(tmp).write_bytes(data)  # a full disk fails here, in one OSError
            _fsync(tmp)
            os.replace(tmp, target)
            _fsync_dir(target.parent)
        except BaseException as exc:
            with contextlib.suppress(OSError):
                os.unlink(tmp)
            if isinstance(exc, InstrumentError) and not str(exc).startswith(f"{self.path}: "):
                raise InstrumentError(f"{self.path}: {exc}") from None  # a shot refused: the archive named
            if isinstance(exc, (InstrumentError, KeyboardInterrupt, SystemExit)) or not isinstance(exc, Exception):
                raise
            raise InstrumentError(f"{self.path}: cannot append: {cause(exc)}") from None
        return ids

    def _write(self, f, entries) -> list:
        """Layout 2: the shots written into the archive's copy."""
        start = max([int(n.split("_", 1)[1]) for n in shot_names(f)] + [0]) + 1
        ids = [start + i for i in range(len(entries))]
        checked: dict = {}
        for shot_id, e in zip(ids, entries):
            write_entry(f, shot_id, e, checked)
        f.attrs.update({"NX_class": "NXroot", "creator": "sonic-rig", "layout_version": LAYOUT_VERSION,
                        "layout": LAYOUT2_TEXT, "file_name": self.path.name})
        f.attrs["default"] = shot_names(f)[-1] if shot_names(f) else ""
        root_seal(f)
        return ids

    @contextlib.contextmanager
    def _lock(self):
        """Hold ``ARCHIVE.h5.lock`` while the block runs (instruments.files.folder_lock,
        waiting for another writer). Where the block fails, or the archive does not exist
        after it, the lock file and the folders this run created are removed: a failed write
        leaves nothing behind."""
        with contextlib.ExitStack() as held:
            try:
                held.enter_context(folder_lock(self.path.parent, self.path.name + ".lock", blocking=True,
                                               keep=self.path.exists))
            except OSError as exc:
                raise InstrumentError(f"{self.path}: cannot write an archive there ({exc.strerror})") from None
            yield

    def _drop_stale_temporaries(self, every: bool = False):
        """Remove the temporary files of writers killed before their rename: the master's
        (beside it), and with ``every`` the parts' too (``rig upgrade``; an append rewrites a
        stale part's temporary under its name, ``_transaction``)."""
        stale_parts = folder(self.path).glob(".*.tmp") if every else []
        for stale in [*self.path.parent.glob(f".{self.path.name}.*.tmp"), *stale_parts]:
            with contextlib.suppress(OSError):
                stale.unlink()  # we hold the lock: no live writer owns it

    # --- reading --------------------------------------------------------------------
    def _open(self, path=None, current: bool = True) -> h5py.File:
        """The archive opened for reading (instruments/archive/opening.py)."""
        return open_archive(path or self.path, current)

    def ids(self) -> list:
        with self._open() as f:
            return [int(n.split("_", 1)[1]) for n in shot_names(f)]

    def read(self, shot_id: int, verify: bool = True, with_truth: bool = True) -> Entry:
        """The stored shot as the same record objects the scope produces; with ``verify``,
        the checksums of what it returns first (its table's rows but its plot's: the time
        axis and attributes, which ``rig verify`` checks) and of what it shares (shared.py:
        once per version of its file; the truth's read-only forces shared by a scene's shots,
        with or without ``verify``). The shot is read from the part its master's link names;
        the master and the parts read last stay open while the files there are those opened."""
        import h5py

        if isinstance(shot_id, bool) or not isinstance(shot_id, numbers.Integral) or shot_id < 1:
            raise InstrumentError(f"shot_id = {shot_id!r}: a shot's number, a whole number >= 1 (an int)")
        with self._reader() as (f, parts):
            name = f"shot_{shot_id:06d}"
            try:
                g = parts.group(f, name)
            except KeyError:
                raise InstrumentError(f"{self.path}: no shot {shot_id} (shots: {id_range(f)})") from None
            except Exception as exc:  # noqa: BLE001 - a missing or damaged part, one line
                raise InstrumentError(f"{self.path}: shot {shot_id}: unreadable ({cause(exc)})") from None
            try:
                layout = attribute_or(h5py.h5o.open(g.id, b"/"), "layout_version")  # of the file that holds it
                if not verify:
                    return read_shot(g, self.path, with_truth, layout=layout,
                                     truth=self._shared.unchecked_truth(f, parts, g) if with_truth else None)
                where = f"{self.path}: shot {shot_id}"
                return checked_shot(g, self.path, where, layout, self._shared.check(f, parts, g, where, with_truth),
                                    with_truth)
            except InstrumentError:
                raise
            except Exception as exc:  # noqa: BLE001 - a damaged file, one line
                raise InstrumentError(f"{self.path}: shot {shot_id}: unreadable ({cause(exc)})") from None

    @contextlib.contextmanager
    def _reader(self):
        """(the master open for reading, the parts read last): kept open from one read to
        the next while the file at each path is the one it was opened from (links.OpenParts;
        an append puts a new master in place, which the next read opens)."""
        with self._reading:
            yield self._master.file(str(self.path), self._open), self._parts

    def verify(self) -> dict:
        """Check the whole archive: {"shots", "ok", "bad"}; each bad row names the shot
        ("shot"; None for what is shared or the file itself), the shots it touches
        ("shots"), the dataset or attribute ("where") and the reason. Never raises."""
        try:
            f = self._open()
        except InstrumentError as exc:
            return {"shots": 0, "ok": 0, "bad": [{"shot": None, "shots": [], "where": str(self.path),
                                                  "reason": str(exc).removeprefix(f"{self.path}: ")}]}
        with f:
            try:
                return check(f)
            except Exception as exc:  # noqa: BLE001 - a safety net: damage is a finding, never a crash
                return {"shots": 0, "ok": 0, "bad": [{"shot": None, "shots": [], "where": str(self.path),
                                                      "reason": f"unreadable ({cause(exc)})"}]}

    def digests(self) -> dict:
        """{shot id: the SHA-256 of its raw data}, as stored (no shot read)."""
        with self._open() as f, OpenParts() as parts:
            return {int(n.split("_", 1)[1]): stored_raw_digest(parts.group(f, n)) for n in shot_names(f)}

    def summary(self) -> list:
        """One row per shot: id, title, start time (and what it is), simulated, scene, seed,
        channels, triggered, source files, the striker's settings; a shot that cannot be
        read: its id and "damaged" (why), the other shots' rows still given."""
        rows = []
        with self._open() as f, OpenParts() as parts:
            for name in shot_names(f):
                try:
                    rows.append(summary_row(read_shot(parts.group(f, name), self.path, with_truth=False)))
                except Exception as exc:  # noqa: BLE001 - a damaged shot, one row
                    rows.append({"shot": int(name.split("_", 1)[1]), "damaged": f"unreadable ({cause(exc)})"})
        return rows


def _fsync_dir(path):  # a folder's sync, where the system offers one
    with contextlib.suppress(OSError):
        _fsync(path)

