"""solve(problem, t_end, save, method, accuracy | dt) -> Solution."""
from __future__ import annotations

import math
import time

import numpy as np

from rig.errors import RigError, invalid
from rig.model.chain import Chain
from rig.solver.kernels.integrators import integrate
from rig.solver.methods import DEFAULT_METHOD
from rig.solver.methods import method as get_method
from rig.solver.problem import ChainProblem
from rig.solver.saveat import SaveAt
from rig.solver.solution import KernelReport, Solution, SolverStats, Status
from rig.solver.stepsize import Stepping, checked_accuracy, default_step, stability_limit

MAX_CHECKS = 50  # energy / momentum / blow-up checks per solve (each one O(N))


def time_grid(t_end: float, dt: float, sample_interval: float) -> tuple:
    """(steps, step, output samples): whole steps of at most dt (s) that end exactly at t_end,
    and the output grid t = j * sample_interval up to t_end."""
    n_steps = max(1, math.ceil(t_end / dt * (1 - 1e-12)))
    return n_steps, t_end / n_steps, int(math.floor(t_end / sample_interval * (1 + 1e-12))) + 1


def frame_origin(chain) -> np.ndarray:
    """Where each moving body's frame position is measured from (m, down from bead 0's
    equilibrium centre): the striker's far end at impact, then each bead's equilibrium."""
    x_eq = chain.equilibrium_positions()
    if chain.striker is None:
        return x_eq
    top = chain.beads[0].radius + chain.striker.gap + chain.striker.length
    return np.concatenate(([-top], x_eq))


def problem_of(chain_or_problem) -> ChainProblem:
    """The ChainProblem of a Chain (or the problem itself)."""
    if isinstance(chain_or_problem, ChainProblem):
        return chain_or_problem
    if isinstance(chain_or_problem, Chain):
        return ChainProblem.from_chain(chain_or_problem)
    raise invalid("problem", type(chain_or_problem).__name__, "a Chain or a ChainProblem")


def solve(problem: ChainProblem | Chain, t_end: float, *, save: SaveAt | None = None,
          method: str = DEFAULT_METHOD, accuracy: float | None = None,
          dt: float | Stepping | None = None) -> Solution:
    """Integrate ``problem`` (a ChainProblem, or a Chain) from the impact (t = 0) to
    ``t_end`` (s), recording what ``save`` names (default: nothing but the final state).

    The step is ``dt`` (s, single rate; or a Stepping, possibly multirate) when given,
    else chosen from ``accuracy`` (target relative force error over the whole chain,
    default 1e-4; see rig/stepsize.py). A dt beyond the method's stability limit for this
    chain is refused.
    """
    m = get_method(method)
    problem = problem_of(problem)
    save = SaveAt() if save is None else save
    if not isinstance(t_end, (int, float)) or not math.isfinite(t_end) or t_end <= 0:
        raise invalid("t_end", t_end, "end time must be a finite number > 0 s")
    if dt is not None:
        if accuracy is not None:
            raise invalid("dt", dt, "give either dt or accuracy, not both")
        stepping = dt if isinstance(dt, Stepping) else Stepping(dt)
        if not (isinstance(stepping.dt, (int, float)) and math.isfinite(stepping.dt) and stepping.dt > 0):
            raise invalid("dt", dt, "time step must be a finite number > 0 s")
        limit = stability_limit(problem, m, stepping.head)
        if stepping.dt > limit:
            raise RigError(
                f"dt = {stepping.dt:.4g} s is beyond the stability limit of {m.name} for this chain "
                f"(about {limit:.4g} s at the estimated peak forces); use dt <= {limit:.3g} s "
                f"or leave dt unset to choose it from the accuracy target")
    else:
        accuracy = checked_accuracy(accuracy)
        stepping = default_step(problem, m, accuracy)
    if stepping.head and (problem.chain.law.dissipative or stepping.head >= problem.n_bodies - 2):
        raise invalid("dt.head", stepping.head, "a multirate head needs a conservative chain longer than the head")
    ch_slot, ch_weight = save.channels(problem.offset)
    n_steps, step, n_out = time_grid(t_end, min(stepping.dt, t_end), save.sample_interval)
    sub = stepping.substeps(step, m.drifts)
    out = np.zeros((len(save.names), n_out))
    if save.frame_interval is not None:
        n_frames = int(math.floor(t_end / save.frame_interval * (1 + 1e-12))) + 1
        frame_dt = save.frame_interval
    else:
        n_frames, frame_dt = 0, 1.0
    frames = np.zeros((n_frames, problem.n_bodies))
    u = problem.u0.copy()
    v = problem.v0.copy()
    diag = np.zeros(6)
    check_every = max(1, n_steps // MAX_CHECKS)

    args = (problem.mass, problem.invm, problem.bias, problem.load, problem.A, problem.d0,
            problem.damping, problem.chain.law.code, np.array(m.drifts), np.array(m.kicks), step)
    mid = (stepping.head, sub)
    tail = (problem.sched_body, problem.sched_t, problem.sched_f,
            ch_slot, ch_weight, save.sample_interval, out, frame_dt, frames,
            check_every, problem.d_limit, problem.wall_slot,
            problem.energy_scale, problem.momentum_scale, diag)
    integrate(u.copy(), v.copy(), *args, 0, *mid, *tail)  # load the compiled kernel before timing
    t0 = time.perf_counter()
    integrate(u, v, *args, n_steps, *mid, *tail)
    wall = time.perf_counter() - t0
    report = KernelReport.of(diag)
    if report.status is not Status.SUCCESS:
        raise RigError(f"{report.status.message} (near t = {report.end_time_s:.4g} s, "
                       f"dt = {step:.4g} s, method {m.name})")
    stats = SolverStats(m.name, step, n_steps, n_steps * m.force_evaluations, wall,
                        report.energy_error, report.momentum_error, report.wall_impulse_Ns,
                        None if dt is not None else float(accuracy))
    moving = slice(0, problem.n_bodies - (1 if problem.wall_slot else 0))
    frames_abs = frames[:, moving] + frame_origin(problem.chain) if n_frames else None
    return Solution(dict(zip(save.names, out)), save.sample_interval, frames_abs,
                    save.frame_interval, u[moving].copy(), v[moving].copy(), stats, problem,
                    report.status)
