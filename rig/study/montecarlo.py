"""Monte Carlo studies over many virtual shots (`rig mc`).

A Study is data: a scene, overrides, the uncertain inputs, the number of shots, one seed.
Shot i always belongs to batch i // batch_size and draws its inputs from child i of the
study's numpy SeedSequence, so results do not depend on the executor or the number of
workers, and any shot can be fired again alone (``refire``). A batch is solved by the
batched kernel (one step for its shots, stored per shot), then each shot goes through
the instruments and the analysis. Every finished batch is written to its own file at once
(atomically), so an interrupted study keeps what it finished and a re-run resumes.
"""
from __future__ import annotations

import contextlib
import functools
import gc
import math
import hashlib
import json
import os
import tempfile
from dataclasses import asdict, dataclass, replace
from pathlib import Path

import h5py
import numpy as np

from instruments.archive import Archive
from instruments.pipeline import analyze_record

from rig.experiment.entry import shot_entry
from rig.experiment import scene as scene_io
from rig.solver.ensemble import ensemble_step, solve_ensemble
from rig.errors import RigError, invalid
from rig.experiment.measure import midway_static_force, setup_for
from rig.experiment.shot import Rig
from rig.solver.problem import ChainProblem
from rig.solver.saveat import SaveAt
from rig.solver.solution import Solution

WINDOWS = ("leading", "record")
TAIL_FWHM = 3.0  # the leading window ends this many widths after the last gauge's leading peak
OUTPUTS = ("speed_m_per_s", "speed_xcorr_m_per_s", "amplitude_N", "averaged_amplitude_N",
           "truth_speed_m_per_s", "truth_amplitude_N", "energy_error", "dt_s")


@dataclass(frozen=True)
class Study:
    scene: str
    dists: tuple
    shots: int
    seed: int = 0
    overrides: tuple = ()
    batch: int = 128
    accuracy: float | None = None
    sobol: bool = False
    truth: bool = False  # also analyse each shot's noise-free truth (slower)
    window: str = "leading"  # "leading": simulate until the leading pulse is past the last gauge; "record": the scene's
    traces: bool = False  # also archive every shot's scope record and truth (DIR/traces/)

    def __post_init__(self):
        if self.window not in WINDOWS:
            raise invalid("--window", self.window, f"one of {', '.join(WINDOWS)}")
        if not isinstance(self.shots, int) or self.shots < 1:
            raise invalid("--shots", self.shots, "a whole number >= 1")
        if self.batch < 1:
            raise invalid("--batch", self.batch, "a whole number >= 1")

    @property
    def keys(self) -> list:
        return [d.key for d in self.dists]

    def spec(self) -> dict:
        return {"scene": str(self.scene), "dists": [asdict(d) for d in self.dists], "shots": self.shots,
                "seed": self.seed, "overrides": list(self.overrides), "batch": self.batch,
                "accuracy": self.accuracy, "sobol": self.sobol, "truth": self.truth, "window": self.window,
                "traces": self.traces}

    def digest(self) -> str:
        return hashlib.sha256(json.dumps(self.spec(), sort_keys=True).encode()).hexdigest()[:16]

    @property
    def n_batches(self) -> int:
        return -(-self.shots // self.batch)

    def shots_of(self, b: int) -> range:
        """The shots of batch b: shot i always belongs to batch i // batch."""
        return range(b * self.batch, min(self.shots, (b + 1) * self.batch))


@functools.lru_cache(maxsize=4)
def nominal_rig(scene: str, overrides: tuple) -> Rig:
    """The study's nominal rig: the scene with its fixed overrides (validated)."""
    return Rig(scene_io.load(scene, overrides))


@functools.lru_cache(maxsize=4)
def nominal_calibration(scene: str, overrides: tuple) -> tuple:
    """(beta, F_0 in N) of the nominal scene's numerics: what an experimenter applies to
    every shot of a study (each shot's own truth is unknown to the analysis)."""
    rig = nominal_rig(scene, overrides)
    return rig.truth_analysis().beta, midway_static_force(rig)


@functools.lru_cache(maxsize=4)
def leading_window(scene: str, overrides: tuple) -> tuple:
    """(duration in s, scope record length, pre-trigger fraction) of a study that needs
    only the leading pulse: simulated until TAIL_FWHM full widths after the nominal shot's
    leading pulse peaks at the last gauge (the cross-correlation searches 2 widths around
    it; the third covers the shot-to-shot spread of its arrival); the scope keeps the
    scene's pre-trigger samples (the baseline comes from them) and records after the
    trigger only as long as the simulation lasts, the trigger taken at the nominal time +
    5% (shot-to-shot spread)."""
    rig = nominal_rig(scene, overrides)
    lead = rig.truth_analysis().leading
    last = lead.get("lower") or lead.get("upper")
    shot = rig.fire(seed=0, truth=False)
    tb, pre = rig.scope.timebase, rig.scope.trigger.pre_trigger
    if not last or not last.get("fwhm") or not shot.scope.triggered:
        return rig.solver.duration, tb.record_length, pre
    duration = min(rig.solver.duration, last["time"] + TAIL_FWHM * last["fwhm"])
    n_pre = int(round(pre * tb.record_length))
    n_post = int((duration - 1.05 * shot.scope.trigger_time) / tb.sample_interval)
    if n_post <= 0 or n_pre + n_post >= tb.record_length:
        return rig.solver.duration, tb.record_length, pre
    return duration, n_pre + n_post, n_pre / (n_pre + n_post)


def sobol_shots(requested: int, n_inputs: int) -> int:
    """Shots of a Sobol design: base x (K + 2), the base the largest power of 2 that fits."""
    base = 2 ** int(math.floor(math.log2(max(1, requested // (n_inputs + 2)))))
    if base < 8:
        raise invalid("--shots", requested, f"a Sobol design over {n_inputs} inputs needs at least "
                                            f"{8 * (n_inputs + 2)} shots")
    return base * (n_inputs + 2)


@functools.lru_cache(maxsize=4)
def sobol_matrix(study: Study):
    """SALib's Sobol design for the study's inputs: (shots, K) and the SALib problem."""
    try:
        from SALib.sample import sobol as sobol_sample
    except ImportError:
        raise RigError("--sobol needs SALib: pip install \".[sobol]\"") from None
    problem = {"num_vars": len(study.dists), "names": study.keys,
               "dists": [d.salib()[0] for d in study.dists], "bounds": [d.salib()[1] for d in study.dists]}
    base = study.shots // (len(study.dists) + 2)
    X = sobol_sample.sample(problem, base, calc_second_order=False, seed=study.seed)
    if X.shape[0] != study.shots:
        raise RigError(f"a Sobol study needs base x (K + 2) shots; use {sobol_shots(study.shots, len(study.dists))}")
    return X, problem


def shot_inputs(study: Study, i: int, n_plain: int, design=None):
    """Shot i's inputs {key: value}, bead masses (or None) and instrument seed."""
    child = np.random.SeedSequence(study.seed, spawn_key=(i,))
    rng = np.random.default_rng(child)
    x, masses = {}, None
    for k, d in enumerate(study.dists):
        if d.key == "chain.bead_mass":
            masses = d.draw(rng, n_plain)
            x[d.key] = float(np.mean(masses))
        else:
            x[d.key] = float(d.draw(rng)) if design is None else float(design[i, k])
    seed = int(child.generate_state(1, np.uint64)[0] >> np.uint64(1))
    return x, masses, seed


def study_duration(study: Study) -> float:
    """Simulated time (s) of each shot of the study."""
    if study.window == "leading":
        return leading_window(study.scene, tuple(study.overrides))[0]
    return nominal_rig(study.scene, tuple(study.overrides)).solver.duration


def _table(v: dict, path) -> dict:
    """The table at ``path`` in v, after copying every table along it (copy on write: the
    scene's other tables stay shared with the nominal values, which nothing modifies)."""
    node = v
    for p in path:
        node[p] = dict(node.get(p, {}))
        node = node[p]
    return node


@functools.lru_cache(maxsize=4)
def study_template(scene: str, overrides: tuple, window: str) -> Rig:
    """What every shot of a study starts from: the scene's values with the solver recording
    at the scope's sampling rate (the scope reads nothing finer) and, in the leading window,
    the window's duration and record: a rig of them, whose parts the shots take over."""
    base = nominal_rig(scene, overrides)
    v = dict(base.values)
    solver, scope = _table(v, ["solver"]), _table(v, ["scope"])
    scope_dt = scope.get("sample_interval")
    if scope_dt and scope_dt > solver.get("sample_interval", 1e-7):
        solver["sample_interval"] = scope_dt
    if window == "leading":
        duration, length, pre = leading_window(scene, overrides)
        solver["duration"], scope["record_length"] = duration, length
        _table(v, ["scope", "trigger"])["pre_trigger"] = pre
    return Rig(base.scene.with_values(v), like=base)


def shot_rig(study: Study, x: dict, masses) -> tuple:
    """Shot inputs x (and bead masses) -> (the shot's rig, its instrument draws)."""
    template = study_template(study.scene, tuple(study.overrides), study.window)
    v = dict(template.values)
    draws = {}
    for key, val in x.items():
        parts = key.split(".")
        if parts[0] == "gauges" and parts[-1] in ("gain", "misalignment"):
            draws.setdefault(parts[1], {})[parts[-1]] = val
            continue
        if key == "chain.bead_mass":
            continue
        _table(v, parts[:-1])[parts[-1]] = val
    return Rig(template.scene.with_values(v), bead_masses=masses, like=template), draws


@contextlib.contextmanager
def _collector_paused():
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


def run_batch(study: Study, b: int) -> dict:
    """Batch b of the study: inputs, outputs and seeds of its shots (plain arrays)."""
    with _collector_paused():
        return _run_batch(study, b)


def study_save(study: Study, rig: Rig) -> SaveAt:
    """What a study's solver records: the gauges' averages (what their plates read) and the
    wall; each gauge's two contacts too where the truth analysis or the traces need them.
    The averages feed the gauges either way, so traces do not change the results."""
    return rig.save_at(contacts=study.truth or study.traces, averages=True)


def _run_batch(study: Study, b: int) -> dict:
    shots = study.shots_of(b)
    lo, hi = shots.start, shots.stop
    base = nominal_rig(study.scene, tuple(study.overrides))
    n_plain = base.values["chain"]["beads"]
    design = sobol_matrix(study)[0] if study.sobol else None
    rigs, draws, seeds, xs = [], [], [], []
    for i in range(lo, hi):
        x, masses, seed = shot_inputs(study, i, n_plain, design)
        try:
            rig, d = shot_rig(study, x, masses)
        except ValueError as exc:
            raise RigError(f"shot {i}: inputs {x} give an impossible rig: {exc}") from None
        rigs.append(rig)
        draws.append(d)
        seeds.append(seed)
        xs.append([x[k] for k in study.keys])
    problems = [ChainProblem.from_chain(r.chain) for r in rigs]
    save = study_save(study, rigs[0])
    t_end = study_duration(study)
    dt = ensemble_step(problems, t_end, base.solver.method, study.accuracy or base.solver.accuracy)
    ens = solve_ensemble(problems, t_end, save=save, dt=dt, method=base.solver.method)
    out = {k: np.full(hi - lo, np.nan) for k in OUTPUTS}
    traces = []
    beta, F0 = nominal_calibration(study.scene, tuple(study.overrides))
    for j, (rig, p) in enumerate(zip(rigs, problems)):
        stats = ens.stats(j, study.accuracy)
        forces = {name: a[j] for name, a in ens.forces.items()}
        rig.use_solution(Solution(forces, ens.sample_interval, None, None, np.empty(0), np.empty(0), stats, p))
        shot = rig.fire(seed=seeds[j], fixed=draws[j], truth=False)
        if study.traces:  # each shot has its own scene values and truth: nothing shared between shots
            e = shot_entry(shot)
            traces.append(replace(e, truth_key=None,
                                  truth_attrs={**e.truth_attrs, "study_shot": lo + j, "study": study.digest()}))
        m = analyze_record(shot.scope, setup_for(rig, beta, F0), train=False)  # leading pulse only
        t = rig.truth_analysis() if study.truth else None
        for key, val in (("speed_m_per_s", m.speed_m_per_s), ("speed_xcorr_m_per_s", m.speed_xcorr_m_per_s),
                         ("amplitude_N", m.amplitude_N), ("averaged_amplitude_N", m.averaged_amplitude_N),
                         ("truth_speed_m_per_s", t and t.speed_m_per_s), ("truth_amplitude_N", t and t.amplitude_N),
                         ("energy_error", stats.energy_error), ("dt_s", ens.dt)):
            out[key][j] = np.nan if val is None else val
    return {"batch": b, "index": np.arange(lo, hi), "inputs": np.array(xs, dtype=float).reshape(hi - lo, len(study.keys)),
            "seeds": np.array(seeds, dtype=np.int64), "outputs": out, "traces": traces}


class Store:
    """DIR/study.json (the study), DIR/batches/batch_NNNNNN.h5 (one per finished batch) and,
    for a study with traces, DIR/traces/batch_NNNNNN.h5 (a shot archive per batch, written
    before the batch counts as finished)."""

    def __init__(self, folder, study: Study):
        self.folder = Path(folder)
        self.study = study
        self.batches = self.folder / "batches"
        self.traces = self.folder / "traces"

    def open(self):
        self.batches.mkdir(parents=True, exist_ok=True)
        meta = self.folder / "study.json"
        spec = {"digest": self.study.digest(), **self.study.spec()}
        if meta.exists():
            old = json.loads(meta.read_text())
            if old.get("digest") != spec["digest"]:
                raise RigError(f"{self.folder} holds another study (scene {old.get('scene')}, "
                               f"{old.get('shots')} shots); give another --out or remove it")
        else:
            meta.write_text(json.dumps(spec, indent=1))
        return self

    def done(self) -> set:
        return {int(p.stem.split("_")[1]) for p in self.batches.glob("batch_*.h5")}

    def write(self, result: dict):
        if result.get("traces"):
            self.traces.mkdir(exist_ok=True)
            archive = self.traces / f"batch_{result['batch']:06d}.h5"
            archive.unlink(missing_ok=True)  # left by an interrupted run: that batch did not finish
            Archive(archive).append(result["traces"])
        fd, tmp = tempfile.mkstemp(dir=self.batches, suffix=".tmp")
        os.close(fd)
        try:
            with h5py.File(tmp, "w") as f:
                f["index"] = result["index"]
                f["inputs"] = result["inputs"]
                f["seeds"] = result["seeds"]
                for k, v in result["outputs"].items():
                    f[f"outputs/{k}"] = v
            os.replace(tmp, self.batches / f"batch_{result['batch']:06d}.h5")
        except BaseException:
            Path(tmp).unlink(missing_ok=True)
            raise

    def collect(self) -> dict:
        """Every finished shot, in shot order."""
        parts = []
        for p in sorted(self.batches.glob("batch_*.h5")):
            with h5py.File(p, "r") as f:
                parts.append({"index": f["index"][()], "inputs": f["inputs"][()], "seeds": f["seeds"][()],
                              "outputs": {k: f[f"outputs/{k}"][()] for k in f["outputs"]}})
        if not parts:
            return {"index": np.zeros(0, int), "inputs": np.zeros((0, len(self.study.keys))),
                    "seeds": np.zeros(0, np.int64), "outputs": {k: np.zeros(0) for k in OUTPUTS}}
        order = np.argsort(np.concatenate([q["index"] for q in parts]))
        cat = lambda key: np.concatenate([q[key] for q in parts])[order]  # noqa: E731
        return {"index": cat("index"), "inputs": cat("inputs"), "seeds": cat("seeds"),
                "outputs": {k: np.concatenate([q["outputs"][k] for q in parts])[order] for k in OUTPUTS}}

    def consolidate(self, results: dict, report: dict):
        """DIR/study.h5: every shot's inputs, outputs and seed, and the report."""
        path = self.folder / "study.h5"
        fd, tmp = tempfile.mkstemp(dir=self.folder, suffix=".tmp")
        os.close(fd)
        with h5py.File(tmp, "w") as f:
            f.attrs["study"] = json.dumps(self.study.spec())
            f.attrs["report"] = json.dumps(report, default=float)
            f["shot"] = results["index"]
            f["seed"] = results["seeds"]
            f["seed"].attrs["description"] = "instrument seed; inputs come from SeedSequence(study seed, spawn_key=(shot,))"
            for k, key in enumerate(self.study.keys):
                f[f"inputs/{key}"] = results["inputs"][:, k]
            for k, v in results["outputs"].items():
                f[f"outputs/{k}"] = v
        os.replace(tmp, path)
        return path


def refire(study: Study, i: int) -> dict:
    """Shot i alone, with its stored step: the same outputs as in the study."""
    return {k: v[i - (i // study.batch) * study.batch] for k, v in run_batch(study, i // study.batch)["outputs"].items()}
