"""Monte Carlo benchmark (``rig bench mc [--baseline REV]``): ptfe52_magnetic at the scene's
default accuracy, in the study's leading-pulse window, batches of rig mc's default size, no traces.

- the batched solver alone (the kernel's time, and the whole solve_ensemble call), numba
  threads over chunks of shots (every core), the shots' arrays built beforehand (their
  cost is reported apart);
- the full pipeline (solver, instruments, measured analysis) in one process (numba threads
  over the shots);
- the full pipeline as ``rig mc --workers N`` runs it, one worker process per core: the
  steady rate (shots finished after each worker's first batch, over the time since) and
  the rate of the whole run, worker start-up included;
- where a shot's wall time goes in one process: each stage of a batch (rig/study/batch.py)
  timed apart;
- how it scales with cores (rig/bench/mc_scaling.py, once, after the rounds, this revision
  only): worker processes, a Dask cluster and numba threads at 1, 2, 4, ... cores, with each
  one's parallel efficiency against 2.

Each figure is the median of ``repeats`` in a round (the study runs once a round). With
``--baseline REV`` every round runs the same measurement with revision REV in a
subprocess right after this one (rig/bench/baseline.py); the table gives the medians over
the rounds and the median of the per-round ratios.
"""
from __future__ import annotations

import contextlib
import dataclasses
import os
import statistics
import tempfile
import time
from dataclasses import dataclass

from instruments.analysis.batch import analysed_figures
from instruments.devices import batch as instrument_batch
from rig.experiment.measure import setup_for
from rig.experiment.shot import Rig
from rig.solver.ensemble import solve_ensemble
from rig.solver.saveat import SaveAt
from rig.solver.solution import Solution
from rig.solver.stepsize import Stepping, stepping_at
from rig.study.batch import batch_inputs, collector_paused, input_table, run_batch
from rig.study.distributions import parse_vary
from rig.study.executors import run_study
from rig.study.mc_spec import DEFAULT_BATCH
from rig.study.montecarlo import MonteCarloStudy
from rig.study.nominal import Nominal, nominal
from rig.study.shots import shots_of, wave_speeds, wiring_of
from rig.study.store import Store

VARY = ("striker.velocity=normal(0.89 m/s, 0.01 m/s)", "chain.bead_mass=normal(0.1226 g, 0.0008 g)")
BATCH = DEFAULT_BATCH  # rig mc's
FIGURES = ("solver_kernel_shots_per_s", "solver_shots_per_s", "pipeline_shots_per_s",
           "pipeline_workers_steady_shots_per_s", "pipeline_workers_total_shots_per_s")
SNIPPET = f"""
import json
from rig.bench import mc
mc.BATCH = {BATCH:d}  # a baseline whose default batch differs runs this one's
kw = {{"rounds": 1, "scaling": False}}  # what this revision's run takes of them
print(json.dumps(mc.run(**{{k: v for k, v in kw.items() if k in mc.run.__code__.co_varnames}})))
"""


@dataclass(frozen=True)
class Setting:
    """What every shot of the benchmark's study starts from, as run_batch takes it: the
    nominal rig's template in the study's window, the channels a study records, its pilot
    (the step's calibration) and the stepping the shots take."""

    nominal: Nominal
    template: Rig
    save: SaveAt
    pilot: Solution
    stepping: Stepping

    @classmethod
    def of(cls, study: MonteCarloStudy) -> Setting:
        nom = nominal(study.scene, ())
        template = nom.template(study.window)
        save = template.save_at(contacts=False, averages=True)
        pilot = nom.pilot(study.window, save, study.accuracy)
        return cls(nom, template, save, pilot, stepping_at(pilot.problem, pilot.stats.dt_s))

    def shots(self, study: MonteCarloStudy, lo: int, hi: int) -> tuple:
        """(shots lo..hi-1 as the solver's arrays (rig/study/shots.py), their instruments' seeds)."""
        beads = self.nominal.rig.values["chain"]["beads"]
        drawn = batch_inputs(study, lo, hi, beads)
        values = dict(zip(study.keys, input_table(study.keys, drawn).T))
        return shots_of(self.template, self.pilot.problem, values, [m for _, m, _ in drawn]), [s for *_, s in drawn]


def _solver(study: MonteCarloStudy, shots: int) -> dict:
    setting = Setting.of(study)
    template, save, pilot, dt = setting.template, setting.save, setting.pilot, setting.stepping
    t_end = template.solver.duration
    t0 = time.perf_counter()
    batches = [setting.shots(study, lo, lo + BATCH)[0].problems for lo in range(0, shots, BATCH)]
    arrays = time.perf_counter() - t0
    solve_ensemble(batches[0], t_end, save=save, dt=dt)
    kernel, total = [], []
    for _ in range(3):  # in batches, as a study runs them (the recorded forces take memory)
        t0 = time.perf_counter()
        k = 0.0
        for problems in batches:
            ens = solve_ensemble(problems, t_end, save=save, dt=dt)
            k += ens.wall_s
        total.append(time.perf_counter() - t0)
        kernel.append(k)
    return {"dt_s": ens.dt, "steps": ens.steps, "t_end_s": t_end, "head": dt.head, "substep_s": dt.inner_dt,
            "error_estimate": pilot.stats.error_estimate,
            "solver_kernel_shots_per_s": shots / statistics.median(kernel),
            "solver_shots_per_s": shots / statistics.median(total),
            "arrays_us_per_shot": arrays / shots * 1e6}


WARM_UP = 3  # batches before the timed ones: numba's threads started, and the batches' large arrays
# (tens of MB) reused by the allocator instead of fresh pages faulted in (about a third of a batch's time)


def _one_process(study: MonteCarloStudy) -> dict:
    for b in range(WARM_UP):
        run_batch(study, b)
    wall, cpu = [], []
    for b in range(WARM_UP, WARM_UP + 6):
        t0, c0 = time.perf_counter(), time.process_time()
        run_batch(study, b)
        wall.append(time.perf_counter() - t0)
        cpu.append(time.process_time() - c0)
    return {"pipeline_shots_per_s": BATCH / statistics.median(wall),
            "pipeline_cpu_us_per_shot": statistics.median(cpu) / BATCH * 1e6}


STAGES = {"inputs": "each shot's inputs drawn, the shots' arrays built",
          "solver": "batched solver (the whole call) and the pulse speeds",
          "acquisition": "the instruments' random draws (19,000 normals), the read channels' gauges, front ends, "
                         "trigger and 8-bit codes",
          "analysis": "leading pulses, delays, the judge's rules over the batch (its figures)"}


def _stages(study: MonteCarloStudy, batches: int = 4) -> dict:
    """Wall time per shot (us) of each stage of a batch, run in turn as run_batch runs them
    (numba's threads, Python's cycle collector paused; after WARM_UP batches of the study,
    which is made long enough to hold them)."""
    study = dataclasses.replace(study, shots=max(study.shots, (WARM_UP + batches) * BATCH))
    setting = Setting.of(study)
    template = setting.template
    wiring = wiring_of(template)
    setup = setup_for(template, *setting.nominal.calibration)
    spent = dict.fromkeys(STAGES, 0.0)
    for b in range(WARM_UP + batches):
        with collector_paused():  # as run_batch runs a batch
            t = _stage_times(study, setting, template, wiring, setup, b)
        if b >= WARM_UP:
            for key, t0, t1 in zip(STAGES, t, t[1:]):
                spent[key] += t1 - t0
    return {f"stage_{key}_us_per_shot": v / (batches * BATCH) * 1e6 for key, v in spent.items()}


def _stage_times(study: MonteCarloStudy, setting: Setting, template: Rig, wiring, setup, b: int) -> list:
    """The clock (s) before batch b and after each of its stages."""
    t = [time.perf_counter()]
    shots, seeds = setting.shots(study, b * BATCH, (b + 1) * BATCH)
    t.append(time.perf_counter())
    ens = solve_ensemble(shots.problems, template.solver.duration, save=setting.save, dt=setting.stepping)
    speeds = wave_speeds(template, shots, ens.records, ens.sample_interval)
    t.append(time.perf_counter())
    records = instrument_batch.acquire(ens.records, ens.sample_interval, wiring, seeds, shots.fixed, speeds,
                                       read=(setup.upper.channel, setup.lower.channel))
    t.append(time.perf_counter())
    analysed_figures(records, setup)
    t.append(time.perf_counter())
    return t


def _workers(study: MonteCarloStudy, workers: int) -> dict:
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


def measure(shots: int = 512, study_shots: int = 8192) -> dict:
    """One round of every figure of this revision."""
    import numba

    study = MonteCarloStudy("ptfe52_magnetic", tuple(parse_vary(VARY)), shots, batch=BATCH)
    workers = os.cpu_count() or 1
    out = {"scene": "ptfe52_magnetic", "shots": shots, "threads": numba.get_num_threads(), "workers": workers,
           "study_shots": study_shots, **_solver(study, shots), **_stages(study)}
    out.update(_one_process(MonteCarloStudy("ptfe52_magnetic", tuple(parse_vary(VARY)), study_shots, batch=BATCH)))
    out.update(_workers(MonteCarloStudy("ptfe52_magnetic", tuple(parse_vary(VARY)), study_shots, seed=1, batch=BATCH),
                        workers))
    return out


def run(rounds: int = 3, baseline: str | None = None, scaling: bool = True) -> dict:
    """The figures over ``rounds`` rounds (with ``baseline``'s in turns), then the scaling
    table where ``scaling``."""
    from rig.bench import mc_scaling
    from rig.bench.baseline import ROOT, checkout, machine
    from rig.bench.baseline import measure as measure_in

    runs: dict[str, list] = {"current": [], "baseline": []}
    with checkout(baseline) if baseline else contextlib.nullcontext() as tree:
        for _ in range(rounds):
            runs["current"].append(measure() if tree is None else measure_in(ROOT, SNIPPET, timeout=1800))
            if tree is not None:
                runs["baseline"].append(measure_in(tree, SNIPPET, timeout=1800))
    out = dict(runs["current"][0], rounds=rounds, baseline_rev=baseline, machine=machine())
    for key in FIGURES + tuple(f"stage_{k}_us_per_shot" for k in STAGES):
        out[key] = statistics.median(r[key] for r in runs["current"])
    if runs["baseline"]:
        out["baseline"] = {key: statistics.median(r[key] for r in runs["baseline"]) for key in FIGURES}
        out["ratio"] = {key: statistics.median(c[key] / b[key] for c, b in zip(runs["current"], runs["baseline"]))
                        for key in FIGURES}
    if scaling:
        out["scaling"] = mc_scaling.run(VARY, BATCH)
    return out


def table(r: dict) -> str:
    labels = {"solver_kernel_shots_per_s": f"batched solver, kernel only, {r['threads']} threads",
              "solver_shots_per_s": f"batched solver, the whole call, {r['threads']} threads",
              "pipeline_shots_per_s": f"full pipeline, one process, {r['threads']} threads",
              "pipeline_workers_steady_shots_per_s": f"full pipeline, rig mc --workers {r['workers']}, steady",
              "pipeline_workers_total_shots_per_s": f"full pipeline, rig mc --workers {r['workers']}, "
                                                    f"{r['study_shots']} shots with start-up"}
    base = r.get("baseline")
    head = f"  {'':56s} {'shots/s':>9s}" + (f" {'baseline ' + r['baseline_rev']:>18s} {'ratio':>7s}" if base else "")
    lines = [f"Monte Carlo, {r['scene']} at default accuracy (dt = {r['dt_s'] * 1e9:.0f} ns from the study's pilot, "
             f"estimate {r['error_estimate']:.2g}; {r['steps']} steps to {r['t_end_s'] * 1e3:.3g} ms, the "
             f"leading-pulse window; head of {r['head']} contact(s), substep {r['substep_s'] * 1e9:.0f} ns), "
             f"batches of {BATCH}, medians of {r['rounds']} round(s); machine: {r['machine']}", head]
    for key in FIGURES:
        line = f"  {labels[key]:56s} {r[key]:9.0f}"
        if base:
            line += f" {base[key]:18.0f} {r['ratio'][key]:7.2f}"
        lines.append(line)
    lines.append(f"  CPU per shot of the one-process pipeline: {r['pipeline_cpu_us_per_shot']:.0f} us (all threads); "
                 f"building a shot's arrays (inputs drawn, problem arrays): {r['arrays_us_per_shot']:.0f} us")
    if "stage_inputs_us_per_shot" in r:
        total = sum(r[f"stage_{k}_us_per_shot"] for k in STAGES)
        lines.append(f"  where a shot's wall time goes in one process ({r['threads']} threads), us per shot:")
        for key, what in STAGES.items():
            us = r[f"stage_{key}_us_per_shot"]
            lines.append(f"    {key:12s} {us:7.1f}  {100 * us / total:4.0f}%  {what}")
    if "scaling" in r:
        from rig.bench import mc_scaling

        lines.append(mc_scaling.table(r["scaling"]))
    return "\n".join(lines)
