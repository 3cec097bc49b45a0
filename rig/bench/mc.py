"""Monte Carlo benchmark (``rig bench mc``): ptfe52_magnetic at the scene's default
accuracy, in the study's leading-pulse window, batches of 128 shots.

- the batched solver alone, numba threads over chunks of shots (every core);
- the full pipeline (solver, instruments, measured analysis; no traces) in one process;
- the full pipeline as ``rig mc --workers N`` runs it, one worker process per core: the
  steady rate (shots finished after each worker's first batch, over the time since) and
  the rate of the whole run, worker start-up included.

Medians of 3 (the study runs once: it is long enough to average over many batches)."""
from __future__ import annotations

import os
import statistics
import tempfile
import time

from rig.solver.ensemble import solve_ensemble
from rig.solver.problem import ChainProblem
from rig.solver.stepsize import stepping_at
from rig.study.batch import run_batch, shot_inputs, shot_rig, study_save
from rig.study.distributions import parse_vary
from rig.study.executors import run_study
from rig.study.mc_spec import Study
from rig.study.nominal import nominal
from rig.study.store import Store

VARY = ("striker.velocity=normal(0.89 m/s, 0.01 m/s)", "chain.bead_mass=normal(0.1226 g, 0.0008 g)")
BATCH = 128


def _solver(study: Study, shots: int) -> dict:
    rigs = [shot_rig(study, *shot_inputs(study, i, 52)[:2])[0] for i in range(shots)]
    problems = [ChainProblem.from_chain(r.chain) for r in rigs]
    save = study_save(study, rigs[0])
    t_end = rigs[0].solver.duration
    pilot = nominal(study.scene, ()).pilot(study.window, rigs[0].save_at(contacts=False, averages=True), study.accuracy)
    dt = stepping_at(problems[0], pilot.stats.dt_s)
    solve_ensemble(problems[:8], t_end, save=save, dt=dt)
    kernel, total = [], []
    for _ in range(3):  # in batches, as a study runs them (the recorded forces take memory)
        t0 = time.perf_counter()
        k = 0.0
        for lo in range(0, shots, BATCH):
            ens = solve_ensemble(problems[lo:lo + BATCH], t_end, save=save, dt=dt)
            k += ens.wall_s
        total.append(time.perf_counter() - t0)
        kernel.append(k)
    return {"dt_s": ens.dt, "steps": ens.steps, "t_end_s": t_end, "head": dt.head, "substep_s": dt.inner_dt,
            "solver_kernel_shots_per_s": shots / statistics.median(kernel),
            "solver_shots_per_s": shots / statistics.median(total)}


def _one_process(study: Study) -> float:
    run_batch(study, 0)
    full = []
    for b in range(1, 4):
        t0 = time.perf_counter()
        run_batch(study, b)
        full.append(time.perf_counter() - t0)
    return BATCH / statistics.median(full)


def _workers(study: Study, workers: int) -> dict:
    ticks = []
    with tempfile.TemporaryDirectory() as folder:
        store = Store(folder, study).open()
        t0 = time.perf_counter()
        run_study(study, store, workers=workers, progress=lambda n: ticks.append((time.perf_counter(), n)))
        total = time.perf_counter() - t0
    # each worker's first batch carries its start-up: count from the moment every worker
    # has delivered one
    times = [t for t, _ in ticks]
    settled = times[workers - 1]
    steady = sum(n for _, n in ticks[workers:]) / (times[-1] - settled)
    return {"pipeline_workers_steady_shots_per_s": steady, "pipeline_workers_total_shots_per_s": study.shots / total}


def run(shots: int = 512, study_shots: int = 8192) -> dict:
    import numba

    study = Study("ptfe52_magnetic", tuple(parse_vary(VARY)), shots, batch=BATCH)
    workers = os.cpu_count() or 1
    out = {"scene": "ptfe52_magnetic", "shots": shots, "threads": numba.get_num_threads(), "workers": workers,
           "study_shots": study_shots, **_solver(study, shots),
           "pipeline_shots_per_s": _one_process(study)}
    out.update(_workers(Study("ptfe52_magnetic", tuple(parse_vary(VARY)), study_shots, seed=1, batch=BATCH),
                        workers))
    return out


def table(r: dict) -> str:
    return "\n".join([
        f"Monte Carlo, {r['scene']} at default accuracy (dt = {r['dt_s'] * 1e9:.0f} ns, {r['steps']} steps "
        f"to {r['t_end_s'] * 1e3:.3g} ms, the study's leading-pulse window; multirate head of {r['head']} "
        f"contact(s), substep {r['substep_s'] * 1e9:.0f} ns), batches of {BATCH}",
        f"  batched solver, kernel only, {r['threads']} threads          {r['solver_kernel_shots_per_s']:8.0f} shots/s",
        f"  batched solver, with set-up, {r['threads']} threads          {r['solver_shots_per_s']:8.0f} shots/s",
        f"  full pipeline, one process                      {r['pipeline_shots_per_s']:8.0f} shots/s",
        (f"  full pipeline, rig mc --workers {r['workers']}, steady        "
         f"{r['pipeline_workers_steady_shots_per_s']:8.0f} shots/s"),
        (f"  full pipeline, rig mc --workers {r['workers']}, {r['study_shots']} shots incl. start-up "
         f"{r['pipeline_workers_total_shots_per_s']:6.0f} shots/s")])
