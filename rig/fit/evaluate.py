"""Many virtual shots of candidate parameter sets in one batched solve.

A fit asks the same question of many candidates (its point, the finite-difference
neighbours of its Jacobian, the striker velocities of a speed-amplitude curve): each is a
scene with other values. ``solve_rigs`` builds each candidate's rig, groups the rigs by
chain layout, solves each group in one call of the batched kernel (rig.solver.ensemble) at
the a-priori step of its stiffest member, and installs every shot's solution in its rig,
so that the rig's truth and instruments read it as they read a lone shot.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rig.errors import RigError
from rig.experiment.shot import Rig
from rig.solver.ensemble import solve_ensemble
from rig.solver.methods import method as get_method
from rig.solver.problem import ChainProblem
from rig.solver.solution import Solution, Status
from rig.solver.stepsize import accuracy_step, checked_accuracy, head_contacts, largest_step, stepping_at


def solve_rigs(rigs: list) -> list:
    """Solve every rig's shot over its scene's duration, batched by chain layout; returns
    whether each succeeded (a shot that blew up is False, its rig left without solution)."""
    ok = [False] * len(rigs)
    problems = [ChainProblem.from_chain(r.chain) for r in rigs]
    groups: dict = {}
    for i, (r, p) in enumerate(zip(rigs, problems)):
        key = (p.n_bodies, p.wall_slot, p.offset, p.slip_speed, p.sched_t.size, r.solver.duration,
               r.solver.method, r.solver.accuracy, tuple(sorted(r.save_at().probes)))
        groups.setdefault(key, []).append(i)
    for members in groups.values():
        r0 = rigs[members[0]]
        m = get_method(r0.solver.method)
        t_end = r0.solver.duration
        acc = checked_accuracy(r0.solver.accuracy)
        heads = {head_contacts(problems[i]) for i in members}
        head = heads.pop() if len(heads) == 1 else 0  # one stepping for all: no head unless all share it
        dt = min(min(accuracy_step(problems[i], m, acc, t_end, head), largest_step(problems[i], m, t_end))
                 for i in members)
        stepping = stepping_at(problems[members[0]], dt, head)
        save = r0.save_at()
        ens = solve_ensemble([problems[i] for i in members], t_end, save=save, dt=stepping, method=m.name)
        for e, i in enumerate(members):
            if ens.reports[e].status is not Status.SUCCESS:
                continue
            forces = {name: a[e] for name, a in ens.forces.items()}
            rigs[i].use_solution(Solution(forces, ens.sample_interval, None, None, np.empty(0), np.empty(0),
                                          ens.stats(e, acc), problems[i]))
            ok[i] = True
    return ok


@dataclass(frozen=True)
class Curve:
    """The leading pulse's dynamic contact force F_d (N) and speed V_s (m/s) between the
    gauges (the truth analysis, as the published numerics) at each striker velocity (m/s);
    nan where a shot gave no pulse."""

    velocity: np.ndarray
    force: np.ndarray
    speed: np.ndarray

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


def curves(scene: str, overrides: list, velocities) -> list:
    """The Curve of each candidate (overrides[c]: its scene overrides) at the striker
    ``velocities`` (m/s): one batched solve of all of them. A candidate the scene refuses
    (a value out of a part's range) has no points; RigError if the scene refuses them all."""
    v = np.asarray(velocities, dtype=float)
    F = np.full((len(overrides), v.size), math.nan)
    V = np.full((len(overrides), v.size), math.nan)
    rigs, where, refused = [], [], []
    for c, extra in enumerate(overrides):
        for k, vel in enumerate(v):
            try:
                rigs.append(Rig.from_scene(scene, list(extra) + [f"striker.velocity={float(vel)!r}"]))
                where.append((c, k))
            except RigError as exc:
                refused.append(str(exc))
    if not rigs:
        raise RigError(f"every candidate refused by the scene: {refused[0]}")
    for (c, k), rig, good in zip(where, rigs, solve_rigs(rigs)):
        if good:
            rep = rig.truth_analysis()
            if rep.speed_m_per_s is not None and rep.amplitude_N is not None:
                F[c, k], V[c, k] = rep.amplitude_N, rep.speed_m_per_s
    return [Curve(v, F[c], V[c]) for c in range(len(overrides))]
