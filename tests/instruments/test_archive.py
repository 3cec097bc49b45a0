"""The HDF5 archive: round trip, crash safety, corruption, concurrent reading, openness.

Synthetic scope records (the emulated oscilloscope on a Gaussian pulse) keep these tests
on the measurement side: no rig import.
"""
import contextlib
import json
import os
import signal
import subprocess
import sys
import threading
import time

import h5py
import numpy as np
import pytest

from instruments.archive import Archive, Entry
from instruments.archive.facts import GaugeFact, ShotFacts
from instruments.devices.oscilloscope import ChannelSettings, Oscilloscope, Timebase, Trigger
from instruments.errors import InstrumentError

SCOPE = Oscilloscope(channels={c: ChannelSettings(volts_per_div=0.05) for c in ("CH1", "CH2", "CH3")},
                     timebase=Timebase(2e-7, 10000), trigger=Trigger("CH1", 0.05, "rising", 0.1))
_T = np.arange(40000) * 1e-7


def entry(seed: int, truth=True) -> Entry:
    rng = np.random.default_rng(seed)
    x = 0.2 * np.exp(-(((_T - 1e-3) / 5e-5) ** 2))
    rec = SCOPE.acquire({"CH1": x, "CH2": 0.8 * x, "CH3": 0.5 * x}, 1e-7, rng)
    facts = ShotFacts(1e-7, {"upper": GaugeFact(3, "CH1", 0.01, 0.1, 0.2)}, None, None, {"draw": {"seed": seed}},
                      1e-3, {"method": "synthetic"})
    return Entry(rec, True, seed, "synthetic", "[scene]\nname = 'synthetic'\n", {"probe": "synthetic"},
                 {"wall_force": np.sin(_T[:5000])} if truth else None, facts, "shared")


# a writer appending one shot at a time, which stops at each point of a transaction (it
# prints the point's name) until it reads "go", and prints "commit ID" after each append.
# Writers are forked from one process that has imported the archive and the scope once: a
# line "START" forks a writer (it prints "pid PID") appending shots START, START + 1, ...;
# when that writer ends, its parent prints "exit CODE" (negative: the signal that ended it)
WRITER = r"""
import os, shutil, sys
sys.path[:0] = {paths!r}
from test_archive import entry
import instruments.archive as archive
from instruments.archive import Archive

def pause(event):
    print(event, flush=True)
    if sys.stdin.readline().strip() != "go":
        os._exit(0)

def after(event, function, when=lambda *a: True):
    def hooked(*args, **kw):
        out = function(*args, **kw)
        if when(*args):
            pause(event)
        return out
    return hooked

def write(path, i):
    print("pid", os.getpid(), flush=True)
    a = Archive(path)
    while True:
        ids = a.append([entry(i)])
        print("commit", ids[0], flush=True)
        i += 1

archive.shutil.copyfile = after("copied", shutil.copyfile)
archive._fsync = after("written", archive._fsync, lambda p: str(p).endswith(".tmp"))
archive.os.replace = after("replaced", os.replace)
append = Archive.append
Archive.append = lambda self, entries: (pause("idle"), append(self, entries))[1]
entry(0)  # the scope's kernel is loaded before the first fork, not in every writer
for line in iter(sys.stdin.readline, ""):
    pid = os.fork()
    if pid == 0:
        try:
            write(sys.argv[1], int(line))
        finally:
            os._exit(1)  # a writer never goes on as the forking process
    print("exit", os.waitstatus_to_exitcode(os.waitpid(pid, 0)[1]), flush=True)
"""


def _writers(path):
    """The process that forks the writers on `path` (its own process group: killpg ends all)."""
    code = WRITER.format(paths=[os.path.dirname(__file__), os.getcwd()])
    return subprocess.Popen([sys.executable, "-c", code, str(path)], start_new_session=True,
                            stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)


def _fork_writer(writers, start) -> int:
    """Fork a writer appending shots `start`, `start` + 1, ...; returns its process id."""
    writers.stdin.write(f"{start}\n")
    writers.stdin.flush()
    event = writers.stdout.readline().split()
    assert event[0] == "pid", event
    return int(event[1])


def test_round_trip_is_bit_identical(tmp_path):
    a = Archive(tmp_path / "a.h5")
    shots = [entry(s) for s in range(30)]
    ids = a.append(shots[:10]) + a.append(shots[10:])
    assert ids == list(range(1, 31))
    for i, e in zip(ids, shots):
        back = a.read(i)
        assert back.seed == e.seed and back.settings == e.settings and back.scene_text == e.scene_text
        assert back.facts == e.facts  # the declared facts, checked on read
        for ch, w in e.record.waveforms.items():
            r = back.record[ch]
            assert r.codes.dtype == w.codes.dtype and np.array_equal(r.codes, w.codes)
            assert r.preamble == w.preamble and r.overrange == w.overrange
        assert np.array_equal(back.truth["wall_force"], e.truth["wall_force"])
    with h5py.File(tmp_path / "a.h5") as f:  # the shared truth is stored once
        assert len(f["shared"]) == 1
        assert f["shot_000001/truth/forces"].id == f["shot_000030/truth/forces"].id
        w = shots[0].record["CH1"]  # the plot holds the codes, CF-packed volts, and the packed sample index
        ch1, t = f["shot_000001/data/CH1"], f["shot_000001/data/time"]
        assert np.array_equal(ch1[()], w.codes)
        assert np.allclose(ch1[()] * ch1.attrs["scale_factor"] + ch1.attrs["add_offset"], w.volts(), rtol=1e-12)
        assert np.allclose(t[()] * t.attrs["scale_factor"] + t.attrs["add_offset"], w.time(), rtol=1e-12, atol=1e-18)


# (point, its occurrence within one append): between appends, then inside one, where an
# append writes and renames its part file, then copies, writes and renames the archive's
KILL_POINTS = (("idle", 1), ("copied", 1), ("written", 1), ("replaced", 1), ("written", 2), ("replaced", 2))


@pytest.mark.slow
def test_sigkill_at_every_point_of_an_append_never_loses_a_committed_shot(tmp_path):
    # the writer stops at each point of its transaction until told to go on; the test kills
    # it at a chosen point after a chosen number of commits: events, not wall-clock windows
    path = tmp_path / "crash.h5"
    Archive(path).append([entry(0)])  # every append copies the archive: each point is reached
    plan = [(int(n), *KILL_POINTS[k % len(KILL_POINTS)])
            for k, n in enumerate(np.random.default_rng(2024).integers(0, 3, 20))]
    committed, start, mid_transaction = [1], 1, 0
    writers = _writers(path)
    watchdog = threading.Timer(120, os.killpg, (writers.pid, signal.SIGKILL))  # a hung writer fails, not hangs
    watchdog.start()
    try:
        for n_commits, point, occurrence in plan:
            pid = _fork_writer(writers, start + 1)
            done, reached = [], 0
            for line in writers.stdout:
                event = line.split()
                if event[0] == "commit":
                    done.append(int(event[1]))
                elif len(done) == n_commits and event[0] == point and (reached := reached + 1) == occurrence:
                    os.kill(pid, signal.SIGKILL)
                    mid_transaction += point != "idle"
                    break
                else:
                    writers.stdin.write("go\n")
                    writers.stdin.flush()
            assert writers.stdout.readline().split() == ["exit", str(-signal.SIGKILL)] and len(done) == n_commits
            committed += done
            start += len(done) + 1
            a = Archive(path)
            ids = a.ids()
            assert set(committed) <= set(ids)  # every shot reported committed is there
            report = a.verify()
            assert report["bad"] == [] and report["shots"] == len(ids)
    finally:
        watchdog.cancel()
        os.killpg(writers.pid, signal.SIGKILL)
        writers.communicate()
    assert len(committed) == 1 + sum(n for n, _, _ in plan) and mid_transaction == 16
    n = len(Archive(path).ids())
    assert Archive(path).append([entry(99999)]) == [n + 1]  # the next append works
    assert not list(tmp_path.glob(".crash.h5.*.tmp"))  # stale temporaries were cleaned


def test_flipped_byte_in_a_data_chunk_is_reported_with_the_shot(tmp_path):
    path = tmp_path / "c.h5"
    a = Archive(path)
    a.append([entry(s, truth=False) for s in range(3)])
    with h5py.File(path) as f:  # the chunk lies in the part file the shot's link leads to
        d = f["shot_000002/data/CH2"]
        offset, holder = d.id.get_chunk_info(0).byte_offset, d.file.filename
    with open(holder, "r+b") as fh:
        fh.seek(offset + 100)
        b = fh.read(1)
        fh.seek(offset + 100)
        fh.write(bytes([b[0] ^ 0xFF]))
    report = a.verify()
    assert report["shots"] == 3 and report["ok"] == 2
    assert [b["shot"] for b in report["bad"]] == [2]
    with pytest.raises((OSError, InstrumentError)):
        a.read(2)


def test_truncated_and_foreign_files_give_clear_errors(tmp_path):
    path = tmp_path / "t.h5"
    Archive(path).append([entry(1)])
    data = path.read_bytes()
    path.write_bytes(data[: len(data) // 2])
    with pytest.raises(InstrumentError, match="truncated or damaged"):
        Archive(path).ids()
    assert Archive(path).verify()["bad"][0]["shot"] is None
    junk = tmp_path / "junk.h5"
    junk.write_text("not hdf5")
    with pytest.raises(InstrumentError, match="not an HDF5 file"):
        Archive(junk).read(1)
    with pytest.raises(InstrumentError, match="not an HDF5 file"):
        Archive(junk).append([entry(1)])  # never builds on a broken archive
    assert junk.read_text() == "not hdf5"


def test_reader_sees_only_complete_shots_while_a_writer_appends(tmp_path):
    # the reader opens the archive at every point of the writer's transactions
    path = tmp_path / "live.h5"
    Archive(path).append([entry(0)])
    writers = _writers(path)
    seen = []
    try:
        _fork_writer(writers, 1)
        for line in writers.stdout:
            a = Archive(path)
            ids = a.ids()
            assert a.read(ids[-1]).shot_id == ids[-1]  # sha256 checked: complete, consistent data
            seen.append(len(ids))
            if len(ids) == 6:
                break
            if not line.startswith("commit"):
                writers.stdin.write("go\n")
                writers.stdin.flush()
    finally:
        os.killpg(writers.pid, signal.SIGKILL)
        writers.communicate()
    assert seen[0] == 1 and seen[-1] == 6 and len(seen) > 5 * 4  # read before, inside and after appends
    assert Archive(path).verify()["bad"] == []


def test_files_open_with_plain_h5py_and_xarray(tmp_path):
    xr = pytest.importorskip("xarray")
    path = tmp_path / "x.h5"
    e = entry(5)
    Archive(path).append([e, entry(6, truth=False)])
    with h5py.File(path, "r") as f:
        g = f["shot_000001"]
        assert g.attrs["NX_class"] == "NXentry" and g["data"].attrs["signal"] == "CH1"
        assert json.loads(g.attrs["metadata"])["seed"] == 5
        assert "volts = scale_factor" in f.attrs["layout"] and f.attrs["layout_version"] == 4
        assert g["title"][()].decode() == "synthetic seed 5" and g["start_time"][()].decode().startswith("20")
        for name, obj in _all_datasets(g):
            assert obj.ndim == 0 or (obj.fletcher32 and obj.chunks), name  # arrays carry fletcher32
            assert "units" in obj.attrs or obj.ndim == 0 or name.endswith("sample"), name
        json.loads(g["settings"][()])
    ds = xr.open_dataset(path, group="shot_000001/data", engine="h5netcdf")
    w = e.record["CH1"]
    assert np.allclose(ds["CH1"].values, w.volts(), rtol=1e-12) and ds["CH1"].dims == ("time",)
    assert np.allclose(ds["time"].values, w.time(), rtol=1e-12, atol=1e-18)
    assert ds["CH1"].attrs["units"] == "V" and ds["time"].attrs["units"] == "s"
    tree = xr.open_datatree(path, engine="h5netcdf")  # the whole file
    forces = tree["shot_000001/truth/forces"]
    assert np.array_equal(forces["wall_force"].values, e.truth["wall_force"])
    assert forces["time"].values[1] == pytest.approx(e.facts.sample_interval_s, rel=1e-12)
    assert forces["wall_force"].attrs["units"] == "N" and forces["time"].attrs["units"] == "s"
    assert json.loads(tree["shot_000002"].attrs["metadata"])["seed"] == 6 and "truth" not in tree["shot_000002"]


def _all_datasets(group):
    out = []
    group.visititems(lambda n, o: out.append((n, o)) if isinstance(o, h5py.Dataset) else None)
    return out


def test_a_writer_waiting_on_a_lock_file_its_holder_removes_takes_the_one_at_the_path(tmp_path):
    """A failed first write removes the lock file it created while still holding it; a
    writer that was waiting on that file must not go on holding a file no longer in the
    folder, or a third writer would take a new one and two would write at once."""
    import fcntl
    import threading

    archive = Archive(tmp_path / "shots.h5")
    lock = tmp_path / "shots.h5.lock"
    a_holds, a_may_fail, b_holds, b_may_go = (threading.Event() for _ in range(4))
    seen = {}

    def first():
        with contextlib.suppress(RuntimeError), archive._lock():
            a_holds.set()
            a_may_fail.wait(10)
            raise RuntimeError("the first write fails")

    def second():
        a_holds.wait(10)
        with archive._lock():
            b_holds.set()
            b_may_go.wait(10)

    threads = [threading.Thread(target=first), threading.Thread(target=second)]
    for t in threads:
        t.start()
    a_holds.wait(10)
    time.sleep(0.2)  # the second writer is now waiting on the first's lock file
    a_may_fail.set()
    assert b_holds.wait(10)
    try:
        with open(lock, "a") as third:  # what a third writer opens: the file at the path
            try:
                fcntl.flock(third, fcntl.LOCK_EX | fcntl.LOCK_NB)
                seen["third got it"] = True
                fcntl.flock(third, fcntl.LOCK_UN)
            except BlockingIOError:
                seen["third got it"] = False
    finally:
        b_may_go.set()
        for t in threads:
            t.join(10)
    assert seen == {"third got it": False}
