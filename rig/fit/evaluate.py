"""Many virtual shots of candidate parameter sets in one batched solve.

A fit asks the same question of many candidates (its point, the finite-difference
neighbours of its Jacobian, the striker velocities of a speed-amplitude curve): each is a
scene with other values. ``solve_rigs`` builds each candidate's rig, groups the rigs by
chain layout, solves each group in one call of the batched kernel (rig.solver.ensemble) at
the step of its stiffest member, and installs every shot's solution in its rig, so that
the rig's truth and instruments read it as they read a lone shot.

The step: a fit calibrates it once, at its start values (``calibrate``: the accuracy
control on the start's shots gives the ratio of the step the setting needs to the a-priori
rule's), and every candidate then takes the rule's step for its own chain times that
ratio, without companions, its Solution carrying the pilot's estimate. ``estimates``
checks the estimate elsewhere (the fit reports it at its result). Without a pilot the
step is the a-priori rule's and the Solutions carry no estimate.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rig.errors import RigError
from rig.experiment.measure import leading_end
from rig.experiment.shot import Rig
from rig.solver.ensemble import solve_ensemble
from rig.solver.methods import method as get_method
from rig.solver.problem import ChainProblem
from rig.solver.run import Unstable
from rig.solver.solution import Solution
from rig.solver.stepsize import accuracy_step, checked_accuracy, head_contacts, largest_step, stepping_at

PILOT_BASIS = "fit pilot"
WINDOW_MARGIN = 1.25
"""A fit of leading pulses simulates this many times as long as the start values' latest
leading pulse needs (rig.experiment.measure.leading_end); a candidate whose pulse comes
later is solved again over the scene's whole duration."""
MIN_STEP_FACTOR = 1.0 / 16.0
"""A fit's step is at least this fraction of the a-priori rule's (a fit costs at most 16
times as much as at the rule's step): a record whose error does not fall with the step (a
contact that grazes, closing or not by a hair) would otherwise drive the step down by
orders of magnitude. Its estimate then says the setting was not met."""


@dataclass(frozen=True)
class Pilot:
    """A fit's numerics, calibrated once at its start values (as a study's step is, from
    its nominal shot): the accuracy control (rig.solver.control) run on each of the start's
    shots over ``window_s`` (s; inf: the scenes' own duration). Every later solve takes the
    a-priori step (rig.solver.stepsize.accuracy_step) times ``step_factor``, the smallest
    ratio of the control's step to the rule's over the pilot's shots, so a candidate
    stiffer or softer than the start keeps the start's error relative to its own peak; its
    Solution carries ``estimate``, the largest of the pilot shots' companion estimates
    (basis "fit pilot"). ``accuracy``: the scenes' setting."""

    step_factor: float
    estimate: float
    accuracy: float
    shots: int
    window_s: float = math.inf

    def spec(self) -> dict:
        return {"step_factor": self.step_factor, "estimate": self.estimate, "accuracy": self.accuracy,
                "shots": self.shots, "window_s": self.window_s}


def _problems(rigs: list) -> list:
    return [ChainProblem.from_chain(r.chain) for r in rigs]


def leading_window(rigs: list) -> float:
    """WINDOW_MARGIN x the latest time (s) the rigs' leading pulses need, each shot solved
    at the a-priori step over its scene's duration (at most that duration); inf where a
    shot shows no leading pulse."""
    ends = [leading_end(r.truth_analysis()) if good else None for r, good in zip(rigs, solve_rigs(rigs))]
    found = [end for end in ends if end is not None]
    if not ends or len(found) < len(ends):
        return math.inf
    window = WINDOW_MARGIN * max(found)
    return window if window < min(r.solver.duration for r in rigs) else math.inf


def calibrate(rigs: list, window_s: float = math.inf) -> Pilot:
    """The Pilot of a fit whose start values give these rigs' shots (one per configuration
    and striker velocity), each solved over ``window_s`` (s; inf: its scene's duration;
    the rigs are built for it), the control going no finer than MIN_STEP_FACTOR x the
    rule's step. RigError where a shot cannot be solved."""
    from rig.solver.control import controlled_solve

    factors, estimates = [], []
    for r, p in zip(rigs, _problems(rigs)):
        m, acc, t_end = get_method(r.solver.method), checked_accuracy(r.solver.accuracy), r.solver.duration
        rule = accuracy_step(p, m, acc, t_end, head_contacts(p))
        sol = controlled_solve(p, t_end, r.save_at(), m, acc, shortest=MIN_STEP_FACTOR * rule, strict=False)
        factors.append(sol.stats.dt_s / rule)
        if sol.stats.error_estimate is not None:
            estimates.append(sol.stats.error_estimate)
    return Pilot(min(factors), max(estimates, default=math.nan), checked_accuracy(rigs[0].solver.accuracy),
                 len(rigs), window_s)


def _batches(rigs: list, problems: list, pilot: Pilot | None) -> list:
    """[(members, t_end, method, stepping)]: the rigs grouped by chain layout, each group's
    stepping the smallest over its members of the a-priori step (times the pilot's
    factor) and the largest stable one; one head for all where all share it, else none."""
    groups: dict = {}
    for i, (r, p) in enumerate(zip(rigs, problems)):
        key = (p.n_bodies, p.wall_slot, p.offset, p.slip_speed, p.sched_t.size, r.solver.duration,
               r.solver.method, r.solver.accuracy, tuple(sorted(r.save_at().probes)))
        groups.setdefault(key, []).append(i)
    factor = 1.0 if pilot is None else pilot.step_factor
    out = []
    for members in groups.values():
        r0 = rigs[members[0]]
        m, t_end, acc = get_method(r0.solver.method), r0.solver.duration, checked_accuracy(r0.solver.accuracy)
        heads = {head_contacts(problems[i]) for i in members}
        head = heads.pop() if len(heads) == 1 else 0  # one stepping for all: no head unless all share it
        dt = min(min(factor * accuracy_step(problems[i], m, acc, t_end, head), largest_step(problems[i], m, t_end))
                 for i in members)
        out.append((members, t_end, m, stepping_at(problems[members[0]], dt, head)))
    return out


def solve_rigs(rigs: list, pilot: Pilot | None = None) -> list:
    """Solve every rig's shot over its scene's duration, batched by chain layout (at the
    pilot's calibrated step, or the a-priori one without a pilot); returns whether each
    succeeded (a shot that blew up is False, its rig left without solution). With a pilot,
    each Solution carries the pilot's estimate (basis "fit pilot"); without, none."""
    ok = [False] * len(rigs)
    problems = _problems(rigs)
    for members, t_end, m, stepping in _batches(rigs, problems, pilot):
        r0 = rigs[members[0]]
        acc = checked_accuracy(r0.solver.accuracy)
        ens = solve_ensemble([problems[i] for i in members], t_end, save=r0.save_at(), dt=stepping, method=m.name)
        for e, i in enumerate(members):
            if not ens.succeeded[e]:
                continue
            forces = {name: a[e] for name, a in ens.forces.items()}
            stats = ens.stats(e, acc) if pilot is None else ens.stats(e, acc, pilot.estimate, PILOT_BASIS)
            rigs[i].use_solution(Solution(forces, ens.sample_interval, None, None, np.empty(0), np.empty(0),
                                          stats, problems[i]))
            ok[i] = True
    return ok


def estimates(rigs: list, pilot: Pilot) -> list:
    """The companion estimate (rig.solver.control) of each rig's shot solved as solve_rigs
    solves it with ``pilot``: what the pilot's estimate stands for, checked elsewhere than
    at the start values (nan where a shot blew up)."""
    from rig.solver.control import estimated_solve

    problems = _problems(rigs)
    out = [math.nan] * len(rigs)
    for members, t_end, m, stepping in _batches(rigs, problems, pilot):
        for i in members:
            try:
                sol = estimated_solve(problems[i], t_end, rigs[i].save_at(), m, stepping)
            except Unstable:
                continue
            if sol.stats.error_estimate is not None:
                out[i] = sol.stats.error_estimate
    return out


@dataclass(frozen=True)
class Curve:
    """The leading pulse's dynamic contact force F_d (N) and speed V_s (m/s) between the
    gauges (the truth analysis, as the published numerics) at each striker velocity (m/s);
    nan where a shot gave no pulse. ``reading``: the same shots' gauge readings F_m,e (N,
    the truth analysis's averaged amplitude: the peak of the mean of a gauge bead's two
    dynamic contact forces, averaged over the two gauges) and ``static_force`` the
    precompression F_0 (N, at the contact midway between the gauges), where the shots gave
    them (None: a curve read back from a store that did not keep them)."""

    velocity: np.ndarray
    force: np.ndarray
    speed: np.ndarray
    reading: np.ndarray | None = None
    static_force: np.ndarray | None = None

    def reach(self) -> tuple:
        """(F_d, V_s) of the curve's largest leading pulse (nan, nan where it has none): no
        striker velocity of the curve gives a larger amplitude."""
        ok = np.isfinite(self.force) & np.isfinite(self.speed) & (self.force > 0)
        if not np.any(ok):
            return math.nan, math.nan
        k = int(np.argmax(np.where(ok, self.force, -np.inf)))
        return float(self.force[k]), float(self.speed[k])

    def speed_at(self, F: np.ndarray) -> tuple:
        """(V_s, dlnV/dlnF) at forces F (N): linear in log-log between the curve's points,
        the end slopes beyond them. Raises RigError when fewer than two points are usable."""
        ok = np.isfinite(self.force) & np.isfinite(self.speed) & (self.force > 0) & (self.speed > 0)
        if np.count_nonzero(ok) < 2:
            raise RigError("the model gave fewer than two leading pulses over the striker velocities")
        order = np.argsort(self.force[ok])
        x, y = np.log(self.force[ok][order]), np.log(self.speed[ok][order])
        keep = np.concatenate(([True], np.diff(x) > 1e-9))
        x, y = x[keep], y[keep]
        if x.size < 2:
            raise RigError("the model's leading pulses do not grow with the striker velocity")
        slopes = np.diff(y) / np.diff(x)
        lx = np.log(np.asarray(F, dtype=float))
        k = np.clip(np.searchsorted(x, lx) - 1, 0, x.size - 2)
        return np.exp(y[k] + slopes[k] * (lx - x[k])), slopes[k]


def numerics(pilot: Pilot, rigs: list) -> dict:
    """What a fit reports of its numerics: the pilot's step factor (step_at_floor: the
    pilot stopped at MIN_STEP_FACTOR) and estimate (at the start values), and the largest
    companion estimate of ``rigs`` (the shots of its result) solved as the fit solved them
    (None where one blew up); within_accuracy: both within the scene's accuracy setting."""
    at_fit = estimates(rigs, pilot)
    worst = max(at_fit) if at_fit and all(math.isfinite(e) for e in at_fit) else None
    start = pilot.estimate if math.isfinite(pilot.estimate) else None
    return {"basis": PILOT_BASIS, "accuracy": pilot.accuracy, "step_factor": pilot.step_factor,
            "step_at_floor": pilot.step_factor <= MIN_STEP_FACTOR * 1.01,
            "pilot_shots": pilot.shots, "window_s": pilot.window_s if math.isfinite(pilot.window_s) else None,
            "estimate_at_start": start, "estimate_at_fit": worst,
            "within_accuracy": start is not None and worst is not None and max(start, worst) <= pilot.accuracy}


def shot_rig(scene: str, overrides, velocity: float, duration: float = math.inf) -> Rig:
    """The rig of one shot: the scene with ``overrides``, the striker at ``velocity`` (m/s),
    simulated for ``duration`` (s; inf: the scene's own). RigError where the scene refuses."""
    window = [] if math.isinf(duration) else [f"solver.duration={float(duration)!r}"]
    return Rig.from_scene(scene, list(overrides) + [f"striker.velocity={float(velocity)!r}"] + window)


def shot_rigs(scene: str, overrides: list, velocities, duration: float = math.inf) -> tuple:
    """(rigs, where, refused): the rig of each candidate (overrides[c]) at each striker
    velocity (m/s), simulated for ``duration`` (s; inf: the scene's own), where[j] = (c, k)
    of rigs[j], and the scene's messages for the shots it refused (a value out of a part's
    range)."""
    rigs, where, refused = [], [], []
    for c, extra in enumerate(overrides):
        for k, vel in enumerate(velocities):
            try:
                rigs.append(shot_rig(scene, extra, vel, duration))
                where.append((c, k))
            except RigError as exc:
                refused.append(str(exc))
    return rigs, where, refused


def curves(scene: str, overrides: list, velocities, pilot: Pilot | None = None) -> list:
    """The Curve of each candidate (overrides[c]: its scene overrides) at the striker
    ``velocities`` (m/s): one batched solve of all of them (with ``pilot``: at its step,
    over its window, a shot whose leading pulse ends after the window solved again over the
    scene's duration; without: at the a-priori step). A candidate the scene refuses (a
    value out of a part's range) has no points; RigError if the scene refuses them all."""
    v = np.asarray(velocities, dtype=float)
    F, V, R, F0 = (np.full((len(overrides), v.size), math.nan) for _ in range(4))
    window = math.inf if pilot is None else pilot.window_s
    rigs, where, refused = shot_rigs(scene, overrides, v, window)
    if not rigs:
        raise RigError(f"every candidate refused by the scene: {refused[0]}")
    reports = [r.truth_analysis() if good else None for r, good in zip(rigs, solve_rigs(rigs, pilot))]
    late = [j for j, rep in enumerate(reports) if math.isfinite(window)
            and (rep is None or (leading_end(rep) or math.inf) > window)]
    if late:
        again = [shot_rig(scene, overrides[where[j][0]], v[where[j][1]]) for j in late]
        for j, r, good in zip(late, again, solve_rigs(again, pilot)):
            reports[j] = r.truth_analysis() if good else None
    for (c, k), rep in zip(where, reports):
        if rep is not None and rep.speed_m_per_s is not None and rep.amplitude_N is not None:
            F[c, k], V[c, k] = rep.amplitude_N, rep.speed_m_per_s
            R[c, k], F0[c, k] = rep.averaged_amplitude_N, rep.static_force_N
    return [Curve(v, F[c], V[c], R[c], F0[c]) for c in range(len(overrides))]
