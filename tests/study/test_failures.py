"""A study's bad shots are counted, not fatal; a killed study leaves no orphan and resumes
to the same bits; a Dask study without workers stops after --worker-timeout."""
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import h5py
import numpy as np
import pytest

from rig.cli import main
from rig.errors import RigError
from rig.study.distributions import parse_vary
from rig.study.executors import WorkerWatch, run_study
from rig.study.mc_spec import FAILURES
from rig.study.montecarlo import MonteCarloStudy
from rig.study.store import Store

WIDE = ["--vary", "striker.velocity=truncnormal(0.89 m/s, 0.3 m/s, 0.05 m/s, 3 m/s)",
        "--vary", "gauges.upper.gain=lognormal(1, 0.6)"]


FAILURES_BEFORE = ("none", "impossible inputs (the rig refuses them)", "solver unstable", "the scope did not trigger",
                   "the scope record ends after the simulated window (--window record simulates the whole record)",
                   "non-finite measured speed or amplitude")  # stored as indices: a reason is added, never moved


def _mc(folder, *extra):
    return ["mc", "ptfe52_magnetic", "--shots", "32", "--batch", "16", *WIDE, "--out", str(folder),
            "--quiet", *extra]


def test_a_wide_study_counts_its_failed_shots_and_fails_past_the_threshold(tmp_path, capsys):
    assert main(_mc(tmp_path / "a", "--json")) == 1
    cap = capsys.readouterr()
    report = json.loads(cap.out)
    failed = report["failed"]
    assert 0 < failed["count"] < report["shots"]
    assert sum(failed["reasons"].values()) == failed["count"]
    assert set(failed["reasons"]) <= set(FAILURES[1:])
    assert any("--window record" in why for why in failed["reasons"])  # the realistic cause, named
    # a gain drawn up to 3x runs the upper gauge off the scope's range: counted as clipped (it had been
    # "non-finite measured speed or amplitude"), the report's keys kept
    assert set(failed) == {"count", "share", "reasons"}
    clipped = next(why for why in FAILURES if "clipped" in why)
    assert failed["reasons"].get(clipped, 0) > 0 and FAILURES[:6] == FAILURES_BEFORE
    assert report["speed_m_per_s"]["trials"] == report["shots"] - failed["count"]  # left out visibly
    err = [line for line in cap.err.splitlines() if line.strip()]
    assert len(err) == 1 and "--max-failed" in err[0] and f"{failed['count']} of 32" in err[0]
    with h5py.File(tmp_path / "a" / "study.h5") as f:
        codes = f["outputs/failure"][()]
        assert int(np.count_nonzero(codes)) == failed["count"]
        assert np.all(np.isnan(f["outputs/speed_m_per_s"][()][codes == 4]))
    # the same study with a looser threshold passes, resumed from the stored batches
    assert main(_mc(tmp_path / "a", "--max-failed", "50%")) == 0
    assert "failed: " in capsys.readouterr().out


def test_a_study_whose_every_shot_fails_says_so_in_one_line(tmp_path, capsys):
    # 100 to 300 m/s is far outside the contact law: every shot is unstable; the report
    # and its figures are still written, and stderr holds the one line (no numpy warning)
    import warnings

    argv = ["mc", "ptfe52_magnetic", "--shots", "16", "--vary", "striker.velocity=uniform(100 m/s, 300 m/s)",
            "--out", str(tmp_path / "bad"), "--quiet"]
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)  # numpy's all-nan slice warning reached the terminal
        assert main(argv) == 1
    err = [line for line in capsys.readouterr().err.splitlines() if line.strip()]
    assert err == ["rig mc: error: 16 of 16 shots failed (100.0%, more than --max-failed 5.0%): 16 solver unstable"]
    assert (tmp_path / "bad" / "speed_vs_amplitude.png").is_file()


def test_worker_watch_stops_after_the_timeout_without_workers():
    now = [0.0]
    watch = WorkerWatch(10.0, clock=lambda: now[0])
    watch.check(0, 0)
    now[0] = 9.0
    watch.check(0, 0)  # not yet
    watch.check(2, 0)  # a worker came back: the clock starts again
    now[0] = 15.0
    watch.check(0, 1)
    now[0] = 25.0
    with pytest.raises(RigError, match=r"--worker-timeout.*1 finished batches.*resume"):
        watch.check(0, 1)


def _study(shots=8):
    vary = ["striker.velocity=normal(0.89 m/s, 0.01 m/s)"]
    return MonteCarloStudy("ptfe52_magnetic", tuple(parse_vary(vary)), shots, seed=5, batch=2)


def test_a_dask_study_without_workers_stops_and_resumes(tmp_path):
    distributed = pytest.importorskip("dask.distributed")
    cluster = distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False,
                                       dashboard_address=None)
    client = distributed.Client(cluster)
    try:
        store = Store(tmp_path / "s", _study()).open()
        cluster.scale(0)
        while client.scheduler_info()["workers"]:
            time.sleep(0.05)
        with pytest.raises(RigError, match="--worker-timeout"):  # 0.5 s: it stops at the poll after the first
            run_study(_study(), store, scheduler=cluster.scheduler_address, worker_timeout=0.5)  # that found none
        cluster.scale(1)
        client.wait_for_workers(1)
        assert run_study(_study(), store, scheduler=cluster.scheduler_address, worker_timeout=2.0) == 4
        assert store.done() == {0, 1, 2, 3}
    finally:
        client.close()
        cluster.close()


def _descendants(pid: int) -> set:
    """Every process below ``pid`` (from /proc)."""
    children = {}
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        children.setdefault(int(fields[1]), []).append(int(stat.parent.name))
    out, todo = set(), [pid]
    while todo:
        for c in children.get(todo.pop(), []):
            out.add(c)
            todo.append(c)
    return out


def _alive(pid: int) -> bool:
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0] != "Z"
    except OSError:
        return False


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc; PR_SET_PDEATHSIG is Linux's")
def test_a_killed_study_leaves_no_orphan_and_resumes_bit_identically(tmp_path):
    argv = ["mc", "ptfe52_magnetic", "--shots", "96", "--batch", "2", "--seed", "7", "--quiet",
            "--vary", "striker.velocity=normal(0.89 m/s, 0.01 m/s)"]
    killed = tmp_path / "killed"
    proc = subprocess.Popen([sys.executable, "-m", "rig.cli", *argv, "--workers", "2", "--out", str(killed)],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 240
    while not list((killed / "batches").glob("batch_*.h5")):  # the event: a first batch is stored
        assert proc.poll() is None and time.monotonic() < deadline, "the study ended before a batch was stored"
        time.sleep(0.05)
    workers = _descendants(proc.pid)
    assert len(workers) >= 2
    os.kill(proc.pid, signal.SIGKILL)
    proc.wait()
    deadline = time.monotonic() + 60
    while any(_alive(w) for w in workers) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert not [w for w in workers if _alive(w)], "orphan worker processes"
    assert len(list((killed / "batches").glob("batch_*.h5"))) < 48  # killed before the end
    assert main([*argv, "--out", str(killed)]) == 0  # resumed in-process
    assert main([*argv, "--out", str(tmp_path / "whole")]) == 0  # uninterrupted
    with h5py.File(killed / "study.h5") as a, h5py.File(tmp_path / "whole" / "study.h5") as b:
        for key in a["outputs"]:
            np.testing.assert_array_equal(a[f"outputs/{key}"][()], b[f"outputs/{key}"][()])
        np.testing.assert_array_equal(a["seed"][()], b["seed"][()])


def test_a_failure_code_names_its_reason_as_the_report_counts_it():
    from rig.study.mc_spec import Failure
    from rig.study.report import failures

    assert [int(f) for f in Failure] == list(range(len(FAILURES)))  # every stored code has its reason
    assert [f.message for f in Failure] == list(FAILURES) and FAILURES[:6] == FAILURES_BEFORE
    assert Failure.SHORT_WINDOW == 4 and "--window record" in Failure.SHORT_WINDOW.message
    counted = failures(np.array([0.0, 4, 4, 6]))  # the stored outputs are floats
    assert counted == {"count": 3, "share": 0.75,
                       "reasons": {Failure.SHORT_WINDOW.message: 2, Failure.CLIPPED.message: 1}}
