"""Run a Monte Carlo study to its folder (`rig mc`): check it, open or resume its store,
run the batches not yet stored (progress per batch), collect every shot and write the
report (JCGM 101 summaries, Sobol indices, figures, study.h5, report.json)."""
from __future__ import annotations

import dataclasses
import json
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from instruments.files import write_text
from rig.errors import Interrupted, RigError
from rig.experiment.measure import midway_static_force
from rig.study.distributions import parse_vary
from rig.study.executors import DEFAULT_WORKER_TIMEOUT, run_study
from rig.study.mc_spec import Failure, default_batch
from rig.study.montecarlo import MonteCarloStudy
from rig.study.nominal import nominal
from rig.study.report import failures, figures, jcgm101
from rig.study.sobol import sobol_indices, sobol_matrix, sobol_shots
from rig.study.store import Store, StudyResults
from rig.theory.longwave import solitary_wave_speed


def check(study: MonteCarloStudy):
    """Refuse a study that cannot run, before any shot: no uncertain input, a varied gauge
    the scene does not have, a Sobol design that SALib cannot build."""
    if not study.dists:
        raise RigError("--vary: give at least one uncertain input, "
                       "e.g. striker.velocity=\"normal(0.89 m/s, 0.01 m/s)\"")
    names = [g.name for g in nominal(study.scene, study.overrides).rig.gauges]
    for d in study.dists:
        parts = d.key.split(".")
        if parts[0] == "gauges" and parts[1] not in names:
            raise RigError(f"--vary {d.key}: the scene has no gauge {parts[1]!r} (gauges: {', '.join(names)})")
    if study.sobol:
        sobol_matrix(study)


@dataclass(frozen=True)
class StudyRun:
    """A finished study: its report (the keys of `rig mc --json`) and how many shots ran now."""

    report: dict
    ran_now: int


def described(scene, vary: list, shots: int, folder, seed: int = 0, overrides: tuple = (), batch: int | None = None,
              accuracy: float | None = None, sobol: bool = False, truth: bool = False, window: str = "leading",
              traces: bool = False, threads: int = 1) -> MonteCarloStudy:
    """The study `rig mc` describes: ``vary`` its --vary texts (KEY=DIST); a Sobol design's
    shots (``sobol``: ``shots`` base samples' worth, rig.study.sobol); the batch size
    ``batch``, else the one of the study already in ``folder`` (a study resumed keeps its
    batches), else default_batch(``threads``): ``threads`` the numba threads of a study run
    in this process, 1 for one run by worker processes."""
    dists = tuple(parse_vary(vary))
    given = batch or Store.stored_batch(folder)
    study = MonteCarloStudy(scene, dists, sobol_shots(shots, len(dists)) if sobol else shots, seed, tuple(overrides),
                            given or default_batch(1), accuracy, sobol, truth, window, traces)
    if given or default_batch(threads) == study.batch:
        return study
    return dataclasses.replace(study, batch=default_batch(threads, held_per_shot(study).bytes))


BATCH_COPIES = 2  # copies of a batch's recorded channels counted (measured: 1.1 with everything else a batch holds)


def held_per_shot(study: MonteCarloStudy):
    """One shot of ``study`` as its batches hold it (rig.solver.estimate's RunEstimate of one
    run). A batch of rigs (--truth, --traces, or a key the arrays do not take) holds each
    shot's whole solution: the rig's own estimate. A batch of arrays (rig/study/shots.py)
    holds each shot's recorded channels (its gauges' averages and the wall, at the scope's
    sampling: the study's template) BATCH_COPIES times over the scene's whole record (a
    leading window is shorter), and its scope codes (one byte a sample). ptfe52_magnetic:
    estimated 760 kB a shot; measured 420 kB over the whole record (a batch of 256 at its
    peak, tracemalloc; a test holds the estimate above it) and 130 kB in the leading window
    (resident memory, a batch of 1024)."""
    from rig.study.shots import array_keys

    nom = nominal(study.scene, tuple(study.overrides))
    rig = nom.rig
    rig.check_record()
    one = rig.estimate(controlled=False)
    if study.truth or study.traces or not array_keys(study.keys, rig):
        return one
    shot = nom.template("record")  # what the shots record, over the scene's window
    channels = len(shot.save_at(contacts=False, averages=True).names)
    samples = shot.estimate(controlled=False).samples  # per channel
    codes = len(shot.scope.channels) * shot.scope.timebase.record_length
    return dataclasses.replace(one, bytes=8.0 * samples * channels * BATCH_COPIES + codes)


def cost(study: MonteCarloStudy):
    """The whole study's estimated memory and CPU time (rig.solver.estimate, batches of
    ``study.batch`` shots held at once, each shot as ``held_per_shot``), after refusing
    settings that can give no record (or a made-up one) before any solve."""
    return held_per_shot(study).times(study.shots, min(study.batch, study.shots))


def run_to(folder, study: MonteCarloStudy, workers: int = 1, scheduler: str | None = None, progress=None,
           on_start=None, worker_timeout: float = DEFAULT_WORKER_TIMEOUT, admit=None) -> StudyRun:
    """Run (or resume) ``study`` in ``folder``, held by this run (``Store.held``).
    ``admit(cost)``, where given, is called once the folder is held and before anything is
    solved, with a function giving the study's estimated cost (``cost``): where a caller
    refuses a study too large, or prepares for it (compiles kernels)."""
    with Store(folder, study).held() as store:  # one run at a time into a folder
        if admit is not None:
            admit(lambda: cost(study))
        return run_in(store, study, workers, scheduler, progress, on_start, worker_timeout)


def run_in(store: Store, study: MonteCarloStudy, workers: int = 1, scheduler: str | None = None, progress=None,
           on_start=None, worker_timeout: float = DEFAULT_WORKER_TIMEOUT) -> StudyRun:
    """Run (or resume) ``study`` in ``store``, a folder this run holds. ``progress(n)`` is
    told each finished batch's shots; ``on_start(done)`` how many shots were already stored;
    on Dask the study stops after ``worker_timeout`` s without a live worker."""
    check(study)
    folder = store.folder
    store.open()
    done = sum(len(study.shots_of(b)) for b in store.done())
    if on_start:
        on_start(done)
    t0 = time.perf_counter()
    try:
        run_study(study, store, workers, scheduler, progress, worker_timeout)
    except KeyboardInterrupt:
        kept = sum(len(study.shots_of(b)) for b in store.done())
        raise Interrupted(f"interrupted: {kept} of {study.shots} shots are kept in {folder}; "
                          f"run the same command again to resume") from None
    ran = study.shots - done
    elapsed = time.perf_counter() - t0
    results = store.collect()
    report = summarise(study, results, ran / elapsed if ran else None)
    write_report(Path(folder), study, store, results, report)
    return StudyRun(report, ran)


def summarise(study: MonteCarloStudy, results: StudyResults, shots_per_s) -> dict:
    """The JCGM 101 summary of each output, the inputs, and the Sobol indices if asked."""
    ok = results.outputs["failure"] == Failure.NONE  # failed shots are counted, and left out of every estimate
    out = {k: np.where(ok, v, np.nan) for k, v in results.outputs.items()}
    report = {"shots": int(results.index.size), "shots_per_s": shots_per_s,
              "failed": failures(results.outputs["failure"]),
              "speed_m_per_s": jcgm101(out["speed_m_per_s"]),
              "speed_xcorr_m_per_s": jcgm101(out["speed_xcorr_m_per_s"]),
              "amplitude_N": jcgm101(out["amplitude_N"]),
              "truth_speed_m_per_s": jcgm101(out["truth_speed_m_per_s"]),
              "truth_amplitude_N": jcgm101(out["truth_amplitude_N"]),
              "inputs": {d.key: d.text() for d in study.dists}}
    if study.sobol:
        report["sobol"] = {k: sobol_indices(study, results.inputs, out[k]) for k in ("speed_m_per_s", "amplitude_N")}
    return report


def write_report(folder: Path, study: MonteCarloStudy, store: Store, results: StudyResults, report: dict):
    """The figures (with the Eq (1) curve at the nominal F_0), study.h5 and report.json."""
    base = nominal(study.scene, study.overrides).rig
    F0 = midway_static_force(base)
    bead = base.chain.beads[-1]
    m = bead.material
    amp = results.outputs["amplitude_N"]
    measured = amp[np.isfinite(amp)]
    F = np.linspace(max(measured.min() * 0.8, 1e-3), measured.max() * 1.2, 100) if measured.size else \
        np.linspace(1e-3, 1.0, 100)  # every shot failed: the curve alone, over 1 mN .. 1 N
    figures(folder, results, study.keys,
            (F, solitary_wave_speed(m.E, m.nu, m.rho, bead.diameter, F0, F0 + F), f"Eq (1), F_0 = {F0:.3g} N"))
    store.consolidate(results, report)
    write_text(folder / "report.json", json.dumps(report, indent=1))
