"""HDF5 shot archive (NeXus) that never loses a committed shot, whose appends cost what
they add.

Layout 3 (instruments/archive/parts.py): a small master file (``shots.h5``) whose shots and
shared groups are HDF5 external links into part files (``shots.h5.d/shots_NNNNNN.h5``), one
per transaction, written once and never changed; the groups they hold are those of layout 2
(instruments/archive/layout.py), with their checksums (digest.py, verify.py). Layout 2 (one
file) is read and still appended to; ``rig upgrade`` (``Archive.upgrade``) converts layouts
1 (through legacy.py) and 2 to layout 3; layout 1 is refused with a line that says so.

Appends are transactions under an exclusive lock (``ARCHIVE.h5.lock``). The new shots are
written into a new part: its image is built in memory (HDF5 writes no file itself: an HDF5
write that fails on a full disk leaves the library in a state that can crash the process),
written to a temporary file, flushed to disk (fsync) and renamed into place; then the master
is copied, the links to the new part added, its root sealed, and the copy flushed and put in
place with ``os.replace``; each rename is followed by a sync of its folder. Nothing already
stored is copied: the master holds links only (772 kB at 10,017 shots). A writer killed at
any moment, a power loss or a full disk leaves either the old master or the new one, each
naming only whole parts; a part no master names (a writer killed between the two renames)
is replaced by the next transaction of the same first shot, and a stale temporary file is
removed by the next append. Readers open the master and see one complete version: this is
what SWMR would give, without SWMR's ban on creating groups. An archive of layout 2 grows
by copying the whole file per transaction, as it always did. An I/O failure (a full disk,
no permission) or a damaged archive ends an append with one InstrumentError naming the
archive and the cause; the archive is left as it was.
"""
from __future__ import annotations

import contextlib
import os
import shutil
import tempfile
from pathlib import Path
from typing import TYPE_CHECKING

from ..errors import InstrumentError
from ..files import cause, folder_lock, hdf5_image
from ..files import fsync as _fsync  # a name of this module's own: the crash tests stop a writer after it
from .digest import damage, linked_groups
from .layout import LAYOUT, LAYOUT_VERSION, Entry, raw_digest, write_entry
from .parts import LAYOUT3, PARTS_TEXT, folder, link_into, part_name, recorded_members, stored_shared, with_new
from .reader import read_entry
from .verify import addresses, check, compact, root_seal, sealed_members, shot_names

if TYPE_CHECKING:  # h5py itself is imported where a file is opened
    import h5py

__all__ = ["Archive", "Entry", "raw_digest"]

class Archive:
    """A shot archive at ``path`` (created on the first append)."""

    def __init__(self, path):
        self.path = Path(path)
        self._sound_shared = {}  # {(file, shared group): (the file's identity, its addresses)}, found intact

    # --- writing --------------------------------------------------------------------
    def append(self, entries) -> list:
        """Append shots in one transaction; returns their ids. All or nothing. An archive of
        layout 2 grows in layout 2 (a copy per transaction) until ``rig upgrade``."""
        entries = list(entries)
        with self._lock():
            self._drop_stale_temporaries()
            if self.path.exists():
                with self._open() as f:
                    version = f.attrs.get("layout_version")
                if version == LAYOUT_VERSION:
                    return self._transaction(lambda f: self._write(f, entries), True)
            return self._commit(entries)

    def upgrade(self) -> int:
        """Rewrite an archive of layout 1 or 2 in layout 3 (one transaction); returns the
        number of shots. An archive of layout 3 is left as it is (0); one of layout 2 that
        does not verify is refused (InstrumentError): converting it would accept its damage."""
        from .legacy import read_legacy_entry

        with self._lock():
            with self._open(current=False) as f:
                version = f.attrs.get("layout_version")
                if version == LAYOUT3:
                    return 0
                bad = check(f)["bad"] if version == LAYOUT_VERSION else []
                if bad:
                    raise InstrumentError(f"{self.path}: {len(bad)} problem{'' if len(bad) == 1 else 's'} (first: "
                                          f"{bad[0]['where']}: {bad[0]['reason']}); `rig verify` lists them; an "
                                          "archive is converted only when it verifies")
                if version == LAYOUT_VERSION:
                    entries = [read_entry(f[n], self.path, keyed=True) for n in shot_names(f)]
                else:
                    entries = [read_legacy_entry(f[n], self.path) for n in shot_names(f)]
            self._drop_stale_temporaries()
            return len(self._commit(entries, [e.shot_id for e in entries], fresh=True))

    def lists_members(self) -> bool:
        """Whether the root records its member lists (instruments/archive/verify.py): False
        for layout 1 and for a layout-2 archive sealed before they were."""
        with self._open(current=False) as f:
            return sealed_members(f)

    def _commit(self, entries, ids=None, fresh: bool = False) -> list:
        """Layout 3 (instruments/archive/parts.py): the new shots into a part file of their
        own, written whole beside the master, then a copy of the small master that links to
        them put in place. A writer stopped between the two leaves a part no master names,
        which the next transaction of the same first shot replaces."""
        master = None if fresh or not self.path.exists() else self._open()
        with contextlib.ExitStack() as held:
            if master is not None:
                held.enter_context(master)
            try:
                members = recorded_members(master) if master is not None else {"/": [], "/shared": []}
                names = [n for n in members["/"] if n.startswith("shot_")]
                stored = stored_shared(master) if master is not None else {}
            except Exception as exc:  # noqa: BLE001 - a damaged master: one line, nothing written
                raise InstrumentError(f"{self.path}: cannot append: {cause(exc)}") from None
            start = max([int(n.split("_", 1)[1]) for n in names] + [0]) + 1
            ids = ids or [start + i for i in range(len(entries))]
            part = part_name(ids[0]) if ids else part_name(start)
            where = folder(self.path)
            made = not where.exists()
            checked: set = set()

            def fill(f):
                for shot_id, e in zip(ids, entries):
                    write_entry(f, shot_id, e, checked, stored)
                f.attrs.update({"NX_class": "NXroot", "layout_version": LAYOUT3, "part_of": self.path.name})
                return sorted(f["shared"]) if "shared" in f else []

            try:
                where.mkdir(exist_ok=True)
                new_shared = self._transaction(fill, False, where / part)
            except BaseException:
                if made:
                    with contextlib.suppress(OSError):
                        where.rmdir()
                raise
        try:
            self._transaction(lambda f: self._link(f, part, ids, new_shared, members), not fresh and master is not None)
        except BaseException:
            with contextlib.suppress(OSError):
                (where / part).unlink()
                if made:
                    where.rmdir()
            raise
        return ids

    def _link(self, f, part: str, ids: list, new_shared: list, members: dict) -> list:
        """The master's links to a new part's shots and shared groups, and its root sealed
        (``members``: its member lists before, to which the new names are added)."""
        names = [f"shot_{shot_id:06d}" for shot_id in ids]
        for name in names:
            f[name] = link_into(self.path.name, part, f"/{name}")
        if new_shared:
            shared = f.require_group("shared")
            shared.attrs["NX_class"] = "NXcollection"
            for key in new_shared:
                shared[key] = link_into(self.path.name, part, f"/shared/{key}")
        f.attrs.update({"NX_class": "NXroot", "creator": "sonic-rig", "layout_version": LAYOUT3,
                        "layout": PARTS_TEXT + "\n\n" + LAYOUT, "file_name": self.path.name})
        f.attrs["default"] = f"shot_{max(ids):06d}" if ids else f.attrs.get("default", "")
        root_seal(f, compact(with_new(members, names, new_shared)))
        return ids

    def _transaction(self, write, copy: bool, target=None) -> list:
        """Write into a copy of ``target`` (the archive's file) or a new file, then put it in
        place: whole or not at all."""
        target = Path(target or self.path)
        fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".tmp", dir=target.parent)
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
            if isinstance(exc, (InstrumentError, KeyboardInterrupt, SystemExit)) or not isinstance(exc, Exception):
                raise
            raise InstrumentError(f"{self.path}: cannot append: {cause(exc)}") from None
        return ids

    def _write(self, f, entries) -> list:
        """Layout 2: the shots written into the archive's copy."""
        start = max([int(n.split("_", 1)[1]) for n in shot_names(f)] + [0]) + 1
        ids = [start + i for i in range(len(entries))]
        checked: set = set()
        for shot_id, e in zip(ids, entries):
            write_entry(f, shot_id, e, checked)
        f.attrs.update({"NX_class": "NXroot", "creator": "sonic-rig", "layout_version": LAYOUT_VERSION,
                        "layout": LAYOUT, "file_name": self.path.name})
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

    def _drop_stale_temporaries(self):
        stale_parts = folder(self.path).glob(".shots_*.h5.*.tmp")
        for stale in [*self.path.parent.glob(f".{self.path.name}.*.tmp"), *stale_parts]:
            with contextlib.suppress(OSError):
                stale.unlink()  # we hold the lock: no live writer owns it

    # --- reading --------------------------------------------------------------------
    def _open(self, path=None, current: bool = True) -> h5py.File:
        """The archive opened for reading; one InstrumentError if it is missing, not HDF5,
        damaged, foreign, or (``current``) of an older layout."""
        import h5py

        path = Path(path or self.path)
        if not path.exists():
            raise InstrumentError(f"{path}: no such archive")
        check_archive_path(path)
        if not h5py.is_hdf5(path):
            raise InstrumentError(f"{path}: not an HDF5 file")
        try:
            f = h5py.File(path, "r")
            creator, version = f.attrs.get("creator"), f.attrs.get("layout_version")
        except Exception as exc:  # noqa: BLE001 - any failure of a damaged file
            raise InstrumentError(f"{path}: cannot be opened as HDF5 (truncated or damaged?): {cause(exc)}") from None
        if creator != "sonic-rig":
            study = "study" in f.attrs and "outputs" in f  # a Monte Carlo study's results (rig mc)
            f.close()
            if study:
                raise InstrumentError(f"{path}: a Monte Carlo study's results (rig mc), not a shot archive: its "
                                      f"shots' scope records are archived under traces/ when it runs with --traces")
            raise InstrumentError(f"{path}: not a rig archive (an HDF5 file that this project did not write)")
        if current and version not in (LAYOUT_VERSION, LAYOUT3):
            f.close()
            raise InstrumentError(f"{path}: archive layout {version or 1}, this version reads layouts "
                                  f"{LAYOUT_VERSION} and {LAYOUT3}: run `rig upgrade {path}` to convert it")
        return f

    def ids(self) -> list:
        with self._open() as f:
            return [int(n.split("_", 1)[1]) for n in shot_names(f)]

    def read(self, shot_id: int, verify: bool = True, with_truth: bool = True) -> Entry:
        """The stored shot as the same record objects the scope produces; with ``verify``,
        the checksums of what it returns first (all of the shot's table but its NXdata plot,
        which ``rig verify`` checks) and of what it shares."""
        with self._open() as f:
            name = f"shot_{shot_id:06d}"
            if name not in f:
                raise InstrumentError(f"{self.path}: no shot {shot_id} (shots: {_id_range(f)})")
            try:
                if verify:
                    self._check_shot(f, f[name], with_truth)
                e = read_entry(f[name], self.path, with_truth)
            except InstrumentError:
                raise
            except Exception as exc:  # noqa: BLE001 - a damaged file, one line
                raise InstrumentError(f"{self.path}: shot {shot_id}: unreadable ({cause(exc)})") from None
            if verify and raw_digest(e.record) != stored_raw_digest(f[name]):
                raise InstrumentError(f"{self.path}: shot {shot_id}: raw_sha256 does not match the raw data")
            return e

    def _check_shot(self, f, g, with_truth: bool = True):
        """The shot's table, and those of the shared groups it links to (scene text and
        settings, and the truth's forces where ``with_truth``; once per version of the file
        that holds them: a part, never changed, or a layout-2 archive, replaced whole by each
        transaction): a shot read without its truth is not refused for damaged truth forces,
        which it does not read."""
        linked, name = {}, f"{self.path}: shot {int(g.name.rsplit('_', 1)[1])}"
        for key in sorted(linked_groups(g, "/shared/")):
            s = f["shared"][key]
            held = s.file.filename
            st = os.stat(held)
            identity = (st.st_ino, st.st_size, st.st_mtime_ns)
            known = self._sound_shared.get((held, key))
            if known and known[0] == identity:
                linked.update(known[1])
                continue
            here = addresses(s)
            linked.update(here)
            problems = damage(s, {})
            read = problems if with_truth else [p for p in problems if not _truth_item(p)]
            if read:
                raise InstrumentError(f"{name}: shared/{key}/{read[0]}")
            if not problems:
                self._sound_shared[(held, key)] = (identity, here)
        problems = damage(g, linked, read=_read_by_entry)
        if problems:
            raise InstrumentError(f"{name}: {problems[0]}")

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
        with self._open() as f:
            return {int(n.split("_", 1)[1]): stored_raw_digest(f[n]) for n in shot_names(f)}

    def summary(self) -> list:
        """One row per shot: id, title, start time (and what it is), simulated, scene, seed,
        channels, triggered, source files, the striker's settings; a shot that cannot be
        read: its id and "damaged" (why), the other shots' rows still given."""
        rows = []
        with self._open() as f:
            for name in shot_names(f):
                try:
                    e = read_entry(f[name], self.path, with_truth=False)
                except Exception as exc:  # noqa: BLE001 - a damaged shot, one row
                    rows.append({"shot": int(name.split("_", 1)[1]), "damaged": f"unreadable ({cause(exc)})"})
                    continue
                rows.append({"shot": e.shot_id, "title": e.title, "start_time": e.start_time,
                             "start_time_source": e.start_time_source, "simulated": e.simulated,
                             "scene": e.scene, "seed": e.seed, "triggered": e.record.triggered,
                             "channels": sorted(e.record.waveforms), "sources": e.settings.get("source_files", []),
                             "settings": e.settings.get("striker", {})})
        return rows


def check_archive_path(path):
    """InstrumentError where ``path`` cannot be an archive file because it is a directory
    (HDF5 would say only that it is not an HDF5 file)."""
    if Path(path).is_dir():
        raise InstrumentError(f"{path}: is a directory; an archive is a file, e.g. "
                              f"{os.path.join(os.path.normpath(path), 'shots.h5')}")


def stored_raw_digest(g) -> str:
    """The stored SHA-256 of a shot's raw data."""
    value = g["raw_sha256"][()]
    return value.decode() if isinstance(value, bytes) else str(value)


def _id_range(f) -> str:
    ids = [int(n.split("_", 1)[1]) for n in shot_names(f)]
    return f"{ids[0]}..{ids[-1]}" if ids else "none"


def _fsync_dir(path):
    with contextlib.suppress(OSError):
        _fsync(path)


def _read_by_entry(key: str) -> bool:
    """Whether a row of a shot's table is of what a read returns: all but its NXdata plot
    (``data/``: the volts and their time axis, computed from the codes and preambles)."""
    return not key.startswith(("data/", "data@"))


def _truth_item(problem: str) -> bool:
    """Whether a line of digest.damage names the truth's forces (the "forces" group,
    its datasets or attributes) of a shared group."""
    key = problem.removeprefix("attribute ").split(":", 1)[0]
    return key.split("@", 1)[0].split("/", 1)[0] == "forces"
