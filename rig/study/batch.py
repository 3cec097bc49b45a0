"""One batch of a Monte Carlo study: each shot's inputs (from its own SeedSequence child),
then one batched solve of all the shots at the study's step (its nominal pilot's), one
batched acquisition and one batched analysis of the leading pulse, with no rig built per
shot (rig/study/shots.py) where the study varies only what arrays carry; else each shot's
rig, read and analysed as a lone shot is. ``refire`` runs one shot again alone, with the
same numbers."""
from __future__ import annotations

import contextlib
import gc
from dataclasses import dataclass, replace

import numpy as np

from instruments import streams
from instruments.analysis import analyze_record
from instruments.analysis.batch import analysed_figures
from instruments.analysis.verdicts import ARRAY_FIGURES
from instruments.devices import batch as instrument_batch
from instruments.devices.oscilloscope import AcquisitionStatus
from rig.errors import RigError, invalid
from rig.experiment.measure import setup_for
from rig.experiment.shot import Rig
from rig.solver.ensemble import solve_ensemble
from rig.solver.problem import ChainProblem
from rig.solver.saveat import SaveAt
from rig.solver.solution import Solution
from rig.solver.stepsize import stepping_at
from rig.study.mc_spec import OUTPUTS, Failure, MonteCarloSpec
from rig.study.nominal import copied_table, nominal
from rig.study.shots import array_keys, shots_of, wave_speeds, wiring_of
from rig.study.sobol import sobol_matrix


@dataclass(frozen=True, eq=False)
class BatchResult:
    """What batch ``batch`` gives: the shots' indices, inputs (shots, K) in the study's key
    order, instrument seeds, outputs {name: (shots,)} (OUTPUTS; nan where nothing was
    measured; "failure": the shot's Failure code, Failure.NONE (0) for a shot that did not
    fail) and, for a study with traces, each shot's archive Entry."""

    batch: int
    index: np.ndarray
    inputs: np.ndarray
    seeds: np.ndarray
    outputs: dict
    traces: tuple = ()

    @property
    def shots(self) -> int:
        return int(self.index.size)


def shot_inputs(study: MonteCarloSpec, i: int, n_plain: int, design=None):
    """Shot i's inputs {key: value}, bead masses (or None) and instrument seed."""
    return batch_inputs(study, i, i + 1, n_plain, design)[0]


def batch_inputs(study: MonteCarloSpec, lo: int, hi: int, n_plain: int, design=None) -> list:
    """(inputs {key: value}, bead masses or None, instrument seed) of shots lo..hi-1, each
    drawn from its own stream, np.random.default_rng(SeedSequence(study.seed,
    spawn_key=(i,))) (instruments.streams: every shot's draws in one compiled call, the
    numbers that generator gives): in the study's key order, n_plain masses for
    chain.bead_mass, one draw for any other key (none where the Sobol design sets it); the
    instrument seed is the sequence's first 64 bits, halved."""
    if not 0 <= lo <= hi <= study.shots:
        raise invalid("shots", f"{lo}..{hi - 1}", f"shots of the study, 0..{study.shots - 1}")
    sizes = [n_plain if d.key == "chain.bead_mass" else int(design is None) for d in study.dists]
    raw, heads = streams.spawned_draws(study.seed, lo, hi - lo, [d.standard for d in study.dists], sizes)
    edges = np.cumsum([0, *sizes])
    values = [d.from_standard(raw[:, a:b]) for d, a, b in zip(study.dists, edges, edges[1:])]
    columns, masses = [], [None] * (hi - lo)
    for k, (d, v) in enumerate(zip(study.dists, values)):
        if d.key == "chain.bead_mass":
            masses = list(v.copy())  # each shot's row; its input the row's mean
            columns.append(v.mean(axis=1).tolist())
        else:
            columns.append((v[:, 0] if design is None else design[lo:hi, k]).tolist())
    rows = zip(*columns) if columns else [()] * (hi - lo)
    seeds = (heads >> np.uint64(1)).tolist()
    return [(dict(zip(study.keys, row)), m, seed) for row, m, seed in zip(rows, masses, seeds)]


def input_table(keys, drawn: list) -> np.ndarray:
    """(shots, keys) the inputs of batch_inputs' shots ``drawn``, in the order of ``keys``."""
    return np.array([[x[k] for k in keys] for x, *_ in drawn], dtype=float).reshape(len(drawn), len(keys))


def shot_rig(study: MonteCarloSpec, x: dict, masses) -> tuple:
    """Shot inputs x (and bead masses) -> (the shot's rig, its instrument draws)."""
    template = nominal(study.scene, tuple(study.overrides)).template(study.window)
    v = dict(template.values)
    draws: dict = {}
    for key, val in x.items():
        parts = key.split(".")
        if parts[0] == "gauges" and parts[-1] in ("gain", "misalignment"):
            draws.setdefault(parts[1], {})[parts[-1]] = val
            continue
        if key == "chain.bead_mass":
            continue
        copied_table(v, parts[:-1])[parts[-1]] = val
    return Rig(template.scene.with_values(v), bead_masses=masses, like=template), draws


def study_save(study: MonteCarloSpec, rig: Rig) -> SaveAt:
    """What a study's solver records: the gauges' averages (what their plates read) and the
    wall; each gauge's two contacts too where the truth analysis or the traces need them.
    The averages feed the gauges either way, so traces do not change the results."""
    return rig.save_at(contacts=study.truth or study.traces, averages=True)


@contextlib.contextmanager
def collector_paused():
    """Python's cycle collector off while a batch builds its rigs: it would walk the many
    small objects of every rig again and again (a quarter of a batch's time); whatever
    cycles the batch leaves are collected on the next collection after it."""
    was = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if was:
            gc.enable()


def run_batch(study: MonteCarloSpec, b: int) -> BatchResult:
    """Batch b of the study."""
    with collector_paused():
        return _batch(study, b)


def _batch(study: MonteCarloSpec, b: int) -> BatchResult:
    shots = study.shots_of(b)
    lo, hi = shots.start, shots.stop
    nom = nominal(study.scene, tuple(study.overrides))
    base = nom.rig
    design = sobol_matrix(study)[0] if study.sobol else None
    out = {k: np.full(hi - lo, np.nan) for k in OUTPUTS}
    out["failure"][:] = Failure.NONE
    drawn = batch_inputs(study, lo, hi, base.values["chain"]["beads"], design)
    seeds = [seed for *_, seed in drawn]
    xs = input_table(study.keys, drawn)
    template = nom.template(study.window)
    traces: list = []
    if study.truth or study.traces or not array_keys(study.keys, template):
        rigs, draws = {}, {}
        for j, (x, masses, _) in enumerate(drawn):
            try:
                rigs[j], draws[j] = shot_rig(study, x, masses)
            except ValueError:  # inputs no rig can have (a negative velocity): counted, not fatal
                out["failure"][j] = Failure.IMPOSSIBLE
        if rigs:
            _fire_rigs(study, nom, rigs, draws, seeds, out, traces, lo)
    else:
        _fire_arrays(study, nom, template, drawn, xs, out)
    return BatchResult(b, np.arange(lo, hi), xs, np.array(seeds, dtype=np.int64), out, tuple(traces))


def _pilot(study: MonteCarloSpec, nom, template: Rig):
    """(the stepping every shot takes, the pilot's Solution): the step is calibrated once, on
    what every study measures (the gauges' averages, the wall), so that recording the
    contacts too (--truth, --traces) changes no result."""
    pilot = nom.pilot(study.window, template.save_at(contacts=False, averages=True), study.accuracy)
    return stepping_at(pilot.problem, pilot.stats.dt_s), pilot


def _fire_arrays(study: MonteCarloSpec, nom, template: Rig, drawn: list, xs: np.ndarray, out: dict):
    """The batch with no rig built per shot (rig/study/shots.py): one batched solve, one
    batched acquisition and one batched analysis of the leading pulse."""
    dt, pilot = _pilot(study, nom, template)
    shots = shots_of(template, pilot.problem, dict(zip(study.keys, xs.T)), [m for _, m, _ in drawn])
    out["failure"][~shots.possible] = Failure.IMPOSSIBLE
    keep = np.flatnonzero(shots.possible)
    if not keep.size:
        return
    sub = shots if keep.size == len(drawn) else shots.take(keep)  # most batches: every shot possible
    save = template.save_at(contacts=False, averages=True)
    ens = solve_ensemble(sub.problems, template.solver.duration, save=save, dt=dt, method=template.solver.method)
    wiring = wiring_of(template)
    forces = ens.records  # what each gauge reads, in the wiring's order: the bead gauges by name, the wall
    h = ens.sample_interval
    speeds = wave_speeds(template, sub, forces, h)
    setup = setup_for(template, *nom.calibration)
    records = instrument_batch.acquire(forces, h, wiring, [drawn[j][2] for j in keep], sub.fixed, speeds,
                                       read=(setup.upper.channel, setup.lower.channel))  # what the analysis reads
    figures = analysed_figures(records, setup)
    roles = [records.wiring.channels.index(setup.upper.channel), records.wiring.channels.index(setup.lower.channel)]
    clipped = np.any(records.over[:, roles], axis=1)  # a channel the analysis reads ran off the scope's range
    unstable = ~ens.succeeded
    short = ~unstable & (records.status == int(AcquisitionStatus.PAST_INPUT))  # the record ends after the window
    out["failure"][keep[unstable]] = Failure.UNSTABLE
    out["failure"][keep[short]] = Failure.SHORT_WINDOW
    done = ~(unstable | short)
    _outputs(out, keep[done], {name: x[done] for name, x in figures.items()}, None, ens.energy_errors[done], ens.dt,
             records.status[done] == int(AcquisitionStatus.OK), clipped[done])


def _figures(rep) -> dict:
    """A Report's figures as analysed_figures gives a batch's: name -> (1,), nan for None."""
    return {name: np.array([np.nan if getattr(rep, name) is None else getattr(rep, name)], dtype=float)
            for name in ARRAY_FIGURES}


def _outputs(out: dict, rows: np.ndarray, m: dict, t: dict | None, energy_error: np.ndarray, dt: float,
             triggered: np.ndarray, clipped: np.ndarray):
    """The outputs of shots ``rows`` from their measured figures m (and truth figures t, or
    None; name -> (rows,), nan where not given, as analysed_figures gives them), and their
    failures, if any (``clipped``: a gauge channel the analysis reads ran off the scope's
    range)."""
    for key in ("speed_m_per_s", "speed_xcorr_m_per_s", "amplitude_N", "averaged_amplitude_N"):
        out[key][rows] = m[key]
    if t is not None:
        out["truth_speed_m_per_s"][rows], out["truth_amplitude_N"][rows] = t["speed_m_per_s"], t["amplitude_N"]
    out["energy_error"][rows], out["dt_s"][rows] = energy_error, dt
    measured = np.isfinite(m["speed_m_per_s"]) & np.isfinite(m["amplitude_N"])
    out["failure"][rows] = np.select([~triggered, ~measured & clipped, ~measured],
                                     [Failure.NO_TRIGGER, Failure.CLIPPED, Failure.NON_FINITE], Failure.NONE)


def _fire_rigs(study: MonteCarloSpec, nom, rigs: dict, draws: dict, seeds: list, out: dict, traces: list, lo: int):
    """The batch with a rig per shot (a key that changes the rig's parts, --truth,
    --traces): one batched solve, then each shot read and analysed as a lone shot is."""
    base = nom.rig
    problems = [ChainProblem.from_chain(r.chain) for r in rigs.values()]
    t_end = nom.window(study.window).duration
    template = nom.template(study.window)
    dt, pilot = _pilot(study, nom, template)
    ens = solve_ensemble(problems, t_end, save=study_save(study, template), dt=dt, method=base.solver.method)
    beta, F0 = nom.calibration
    setup = setup_for(template, beta, F0)
    for e, ((j, rig), p) in enumerate(zip(rigs.items(), problems)):
        if not ens.succeeded[e]:
            out["failure"][j] = Failure.UNSTABLE
            continue
        stats = ens.stats(e, pilot.stats.accuracy, pilot.stats.error_estimate)
        forces = {name: a[e] for name, a in ens.forces.items()}
        rig.use_solution(Solution(forces, ens.sample_interval, None, None, np.empty(0), np.empty(0), stats, p))
        try:
            shot = rig.fire(seed=seeds[j], fixed=draws[j], truth=False)
        except RigError:  # the scope's record ends after the simulated window
            out["failure"][j] = Failure.SHORT_WINDOW
            continue
        if study.traces:  # each shot has its own scene values and truth: nothing shared between shots
            from rig.experiment.entry import shot_entry  # the archive's Entry (h5py): only with traces

            entry = shot_entry(shot)
            assert entry.facts is not None, "shot_entry writes the shot's facts"
            calibration = {"beta": beta, "static_force_N": F0, "basis": "the study's nominal shot"}  # what it applied
            traces.append(replace(entry, truth_key=None, facts=replace(entry.facts, study_shot=lo + j,
                                                                       study=study.digest(), analysis=calibration)))
        m = analyze_record(shot.scope, setup, train=False)  # leading pulse only
        waves = shot.scope.waveforms
        clipped = any(waves[ch].overrange for ch in (setup.upper.channel, setup.lower.channel) if ch in waves)
        _outputs(out, np.array([j]), _figures(m),
                 _figures(rig.truth_analysis()) if study.truth else None, np.array([stats.energy_error]),
                 ens.dt, np.array([shot.scope.triggered]), np.array([clipped]))


def refire(study: MonteCarloSpec, i: int) -> dict:
    """Shot i alone, with its stored step: the same outputs as in the study."""
    if not 0 <= i < study.shots:
        raise invalid("shot", i, f"a shot of the study, 0..{study.shots - 1}")
    r = run_batch(study, i // study.batch)
    return {k: v[i - r.index[0]] for k, v in r.outputs.items()}
