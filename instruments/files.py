"""Files written whole or not at all, and a folder held by one process at a time.

Every file the rig writes (scope exports, caches, studies, fits, figures, scenes) goes
through ``atomic_write``: it is written to a temporary file in the same folder, flushed to
disk (fsync) and renamed over its name (``os.replace``, atomic on one file system), then the
folder is synced. A full disk, a killed process or a power cut leaves the old file or the
new one, never a truncated or empty one; the temporary file is removed when the write
fails. ``atomic_writes`` does the same for several files at once: all of them are written
before any is renamed, so a failure leaves none of them new.

HDF5 files are built in memory (``hdf5_image``, HDF5's core driver) and their bytes written
by Python: HDF5 that fails part-way through a write to disk is left in a broken state (h5py
then prints tracebacks while it cleans up, and a process can crash), where a failed write
of plain bytes is one OSError.

``left_as_found`` removes what a block added to a folder when the block fails: a refused
run leaves the folder (or its absence) as it was; ``made_folder`` removes the folders a
failed block created and left empty.

``folder_lock`` holds an exclusive ``flock`` on a lock file in a folder for the life of a
run; the OS releases it when the process ends, killed or not, so a dead holder never blocks.
The file names the holder (pid, host, start), which a refusal quotes.
"""
from __future__ import annotations

import contextlib
import errno
import fcntl
import os
import socket
import tempfile
import time
from pathlib import Path

from .errors import InstrumentError


def atomic_write(path, write) -> Path:
    """``write(temporary path)``, flushed to disk, then renamed to ``path``; returns ``path``.
    The file gets the mode a plain ``open`` would give it (0666 less the umask); the
    temporary's name ends in ``path``'s suffix (".tmp.mp4"), for writers that choose the
    format by it."""
    return atomic_writes({path: write})[0]


def atomic_writes(writes: dict) -> list:
    """{path: write} as ``atomic_write`` does one, all written before any is renamed: a
    failure while writing leaves none of them new. Returns the paths."""
    temporaries, path = {}, None
    try:
        for path, write in writes.items():
            path = Path(path)
            temporaries[path] = tmp = _temporary(path)
            write(tmp)
            fsync(tmp)
        for path, tmp in temporaries.items():
            os.replace(tmp, path)
    except BaseException as exc:
        for tmp in temporaries.values():
            with contextlib.suppress(OSError):
                os.unlink(tmp)
        if isinstance(exc, OSError):  # named by the file meant, not its temporary (h5py, numpy name none)
            raise OSError(exc.errno, cause(exc), str(path)) from None
        raise
    for folder in {p.parent for p in temporaries}:
        with contextlib.suppress(OSError):
            fsync(folder)
    return list(temporaries)


def cause(exc: BaseException) -> str:
    """A failure's cause in one line: the OS's words for an I/O error with an errno (ENOSPC:
    'No space left on device'), else the first line of its message."""
    if isinstance(exc, OSError) and exc.errno is not None and exc.errno in errno.errorcode:
        return os.strerror(exc.errno)
    return (str(exc).splitlines() or [type(exc).__name__])[0] or type(exc).__name__


def hdf5_image(fill, image: bytes | None = None, libver: tuple = ("earliest", "latest")) -> tuple:
    """(the bytes of an HDF5 file, what ``fill`` returned): ``fill(h5py.File)`` on a new
    file in memory, or on a copy of ``image`` (an HDF5 file's bytes). Nothing is written to
    disk here. The memory it takes is two to three times the file's size (``image``, HDF5's
    copy of it, the bytes returned)."""
    with hdf5_in_memory(image, libver) as f:
        out = fill(f)
        f.flush()
        return f.id.get_file_image(), out


@contextlib.contextmanager
def hdf5_in_memory(image: bytes | None = None, libver: tuple = ("earliest", "latest")):
    """A new HDF5 file open in memory (HDF5's core driver, no file behind it), or a copy of
    ``image``; ``f.id.get_file_image()`` gives its bytes."""
    import uuid

    import h5py

    fapl = h5py.h5p.create(h5py.h5p.FILE_ACCESS)
    fapl.set_fapl_core(backing_store=False)
    fapl.set_libver_bounds(*(getattr(h5py.h5f, f"LIBVER_{v.upper()}") for v in libver))
    name = f"in-memory-{uuid.uuid4().hex}".encode()  # HDF5 takes two files of one name for one
    if image:
        fapl.set_file_image(image)
        fid = h5py.h5f.open(name, h5py.h5f.ACC_RDWR, fapl=fapl)
    else:
        fid = h5py.h5f.create(name, h5py.h5f.ACC_TRUNC, fapl=fapl)
    with h5py.File(fid) as f:
        yield f


def write_hdf5(path, fill) -> Path:
    """The HDF5 file ``path`` as ``fill(h5py.File)`` makes it, whole or not at all."""
    return atomic_write(path, lambda tmp: Path(tmp).write_bytes(hdf5_image(fill)[0]))


def write_text(path, text: str) -> Path:
    """``text`` (UTF-8) as the whole of ``path``, atomically."""
    return atomic_write(path, lambda tmp: Path(tmp).write_text(text, encoding="utf-8"))


@contextlib.contextmanager
def left_as_found(folder, failures=(Exception,), keep=None):
    """Run a block that writes under ``folder``; where it raises one of ``failures``, remove
    every file and folder under ``folder`` that was not there before the block (and
    ``folder`` itself, with the parents it was created with, where the block created it),
    then re-raise. Where ``keep(exception)`` is true, the files it added stay (work a run
    again resumes from) and only the folders it added and left empty go. What was there
    before stays, as it is. Only for a folder the run owns: what another process adds there
    meanwhile would be removed too."""
    folder = Path(folder).absolute()
    top = first_missing(folder) or folder
    before = tree(top)
    try:
        yield folder
    except failures as exc:
        remove_added(top, before, files=keep is None or not keep(exc))
        raise


@contextlib.contextmanager
def made_folder(folder):
    """Create ``folder`` (with its parents) for a block; where the block fails, remove the
    folders this created that it left empty (a shared folder that others write into too is
    never emptied by this)."""
    folder = Path(folder).absolute()
    top = first_missing(folder)
    folder.mkdir(parents=True, exist_ok=True)
    try:
        yield folder
    except BaseException:
        if top is not None:
            remove_empty(folder, top)
        raise


def first_missing(folder) -> Path | None:
    """The outermost of ``folder`` and its parents that does not exist (what a
    ``mkdir(parents=True)`` of it would create first); None where ``folder`` exists."""
    folder = Path(folder).absolute()
    if folder.exists():
        return None
    while not folder.parent.exists() and folder.parent != folder:
        folder = folder.parent
    return folder


def remove_empty(folder, top):
    """Remove ``folder`` and its parents up to ``top`` (one of them) while they are empty."""
    folder, top = Path(folder).absolute(), Path(top).absolute()
    for path in (folder, *folder.parents):
        try:
            path.rmdir()
        except OSError:  # not empty (or gone): the folders above it hold it
            return
        if path == top:
            return


def tree(folder) -> set:
    """Every path under ``folder`` and ``folder`` itself; empty where it does not exist."""
    folder = Path(folder)
    return {folder, *folder.rglob("*")} if folder.is_dir() else set()


def remove_added(folder, before: set, files: bool = True):
    """Remove what is under ``folder`` (and ``folder``) now that is not in ``before`` (a
    ``tree``): files first (unless ``files`` is false), then the folders left empty,
    deepest first. A folder that holds something from before is kept; a path that cannot be
    removed is left."""
    added = sorted(tree(folder) - set(before), key=lambda p: len(p.parts), reverse=True)
    for path in added:
        with contextlib.suppress(OSError):
            if path.is_dir() and not path.is_symlink():
                path.rmdir()
            elif files:
                path.unlink()


def _temporary(path: Path) -> str:
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp" + path.suffix)
    os.close(fd)
    mask = os.umask(0)
    os.umask(mask)
    os.chmod(tmp, 0o666 & ~mask)  # mkstemp's 0600 would make every written file private
    return tmp


def fsync(path):
    """Flush ``path`` (a file or a folder) to disk."""
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


@contextlib.contextmanager
def folder_lock(folder, name: str, what: str = "", *, blocking: bool = False, keep=lambda: True):
    """Hold ``folder/name`` exclusively while the block runs, the folder made where it is
    missing; the holder writes its name (pid, host, since) into it. Not ``blocking``: held
    by another live process, one InstrumentError naming the folder, the holder and ``what``
    to do; ``blocking``: wait for it. Where the block fails, or ``keep()`` is false after
    it, a lock file this run created is removed while still held (held_lock: a run that
    waited on it takes the file then at the path), and the folders this run made are
    removed where empty: a failed run leaves nothing behind. A folder or lock file that
    cannot be made or opened (no permission, a read-only disk) is an OSError."""
    folder = Path(folder)
    lock = folder / name
    top = first_missing(folder)
    try:
        folder.mkdir(parents=True, exist_ok=True)
        created = not lock.exists()
        try:
            fh = held_lock(lock, blocking)
        except BlockingIOError:
            raise InstrumentError(f"{folder}: in use by another run ({_holder(lock)}); {what}") from None
        with fh:  # closing it releases the lock
            kept = False
            try:
                with contextlib.suppress(OSError):  # the name is for a refusal's message; a full disk stops it later
                    fh.seek(0)
                    fh.truncate()
                    fh.write(f"pid {os.getpid()} on {socket.gethostname()} since "
                             f"{time.strftime('%Y-%m-%dT%H:%M:%S%z')}\n")
                    fh.flush()
                yield lock
                kept = keep()
            finally:
                if created and not kept:
                    lock.unlink(missing_ok=True)
                fcntl.flock(fh, fcntl.LOCK_UN)
    finally:
        if top is not None:
            remove_empty(folder, top)


def held_lock(lock, blocking: bool = True):
    """The file ``lock`` open ("a+") and exclusively held (flock), waiting for it where
    ``blocking``, else BlockingIOError while another holds it. A run that fails removes a
    lock file it created while still holding it: one that opened that file just before then
    holds a file no longer in the folder, so it takes the file now at the path instead (the
    same inode under the path and in its hand): two runs never hold two different files."""
    while True:
        fh = open(lock, "a+")  # noqa: SIM115 - the caller closes it (closing releases the lock)
        try:
            fcntl.flock(fh, fcntl.LOCK_EX | (0 if blocking else fcntl.LOCK_NB))
        except BaseException:
            fh.close()
            raise
        held = os.fstat(fh.fileno())
        try:
            here = os.stat(lock)
        except FileNotFoundError:
            here = None
        if here is not None and (here.st_ino, here.st_dev) == (held.st_ino, held.st_dev):
            return fh
        fh.close()


def _holder(lock: Path) -> str:
    """Who holds ``lock``, as its holder wrote it ("pid 12 on host since ...")."""
    try:
        return " ".join(lock.read_text().split()) or "a process that has not written its name yet"
    except OSError:
        return "a process that has not written its name yet"
