"""Monte Carlo benchmark (``rig bench mc``): for ptfe52_magnetic at the scene's default
accuracy, the batched solver alone (shots/s on this machine's cores, numba threads over
chunks of shots) and the full pipeline (solver, instruments, truth and measured analysis;
one process). Medians of 3."""
from __future__ import annotations

import statistics
import time

import numba

from rig.distributions import parse_vary
from rig.ensemble import ensemble_step, solve_ensemble
from rig.mc import Study, _rig_for, run_batch, shot_inputs

VARY = ("striker.velocity=normal(0.89 m/s, 0.01 m/s)", "chain.bead_mass=normal(0.1226 g, 0.0008 g)")


def run(shots: int = 512, batch: int = 128) -> dict:
    study = Study("ptfe52_magnetic", tuple(parse_vary(VARY)), shots, batch=batch)
    rigs = [_rig_for(study, *shot_inputs(study, i, 52)[:2])[0] for i in range(shots)]
    problems = [r.chain.problem(r.record()) for r in rigs]
    t_end = rigs[0].solver["duration"]
    dt = ensemble_step(problems, t_end)
    solve_ensemble(problems[:8], t_end, dt=dt)
    kernel, total = [], []
    for _ in range(3):  # in batches, as a study runs them (the recorded forces take memory)
        t0 = time.perf_counter()
        k = 0.0
        for lo in range(0, shots, batch):
            ens = solve_ensemble(problems[lo:lo + batch], t_end, dt=dt)
            k += ens.wall_s
        total.append(time.perf_counter() - t0)
        kernel.append(k)
    run_batch(study, 0)
    full = []
    for _ in range(3):
        t0 = time.perf_counter()
        run_batch(study, 1)
        full.append(time.perf_counter() - t0)
    return {"scene": "ptfe52_magnetic", "shots": shots, "threads": numba.get_num_threads(),
            "dt_s": ens.dt, "steps": ens.steps, "t_end_s": t_end, "head": dt.head, "substep_s": dt.inner_dt,
            "solver_kernel_shots_per_s": shots / statistics.median(kernel),
            "solver_shots_per_s": shots / statistics.median(total),
            "pipeline_shots_per_s": batch / statistics.median(full)}


def table(r: dict) -> str:
    return "\n".join([
        f"Monte Carlo, {r['scene']} at default accuracy (dt = {r['dt_s'] * 1e9:.0f} ns, {r['steps']} steps "
        f"to {r['t_end_s'] * 1e3:.3g} ms, the study's leading-pulse window; multirate head of {r['head']} "
        f"contact(s), substep {r['substep_s'] * 1e9:.0f} ns), {r['threads']} threads",
        f"  batched solver, kernel only      {r['solver_kernel_shots_per_s']:8.0f} shots/s",
        f"  batched solver, with set-up      {r['solver_shots_per_s']:8.0f} shots/s",
        f"  full pipeline (one process)      {r['pipeline_shots_per_s']:8.0f} shots/s"])
