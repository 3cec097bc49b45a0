"""Peer solvers for the solver benchmark: the same chain, the same probe, the same grid.

Every peer integrates the same ChainProblem (rig/solver/problem.py): bodies from the top
[striker] + beads + [wall, inverse mass 0], displacement u from static equilibrium (m) and
velocity v (m/s), contact slot i joining bodies i-1 and i with the dynamic force

    f[i] = A[i] max(d, 0)^(3/2) - load[i],  d = d0[i] + u[i-1] - u[i],  f[0] = 0,  f[nb] = -load[nb]

(N), body i accelerated by (f[i] - f[i+1]) invm[i] (m/s^2), conservative Hertz law only.
Each integrates from t = 0 to t_end and records only one probe, the whole contact force of
one slot s, F = A[s] max(d_s, 0)^(3/2) (N), on the grid t_j = j sample_interval,
j = 0 .. floor(t_end / sample_interval) (the grid of rig.solver.solve):

- ``scipy_dop853``: scipy.integrate.solve_ivp, method DOP853, vectorised numpy right-hand
  side, in this process.
- ``numba_dop853``: DOP853 compiled with numba (rig/bench/kernels/dop853.py), Hairer's
  step-size control, the probe from the method's own dense output.
- LAMMPS: rig/bench/lammps.py.

Each returns a PeerRun; cpu_s is the CPU time of the integration only (time.process_time in
process; for a subprocess, the child's user + system time).
"""
from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from rig.errors import RigError, invalid
from rig.model.contact import HERTZ
from rig.solver.problem import ChainProblem
from rig.solver.run import time_grid
from rig.solver.saveat import SaveAt

POSITION_SCALE = 1e-5  # m: the absolute tolerance of a displacement is rtol x this
VELOCITY_FLOOR = 1e-3  # m/s: ... of a velocity, rtol x max(largest initial speed, this)


@dataclass(frozen=True)
class PeerRun:
    """One run of a peer: name and setting (e.g. "numba-DOP853", "rtol=1e-08"); force: the
    probe on the output grid (N); cpu_s, wall_s: CPU and wall time of the integration (s);
    rhs_evaluations: evaluations of the chain's forces (all bodies); steps: accepted steps;
    note: what the times include and anything else a reader of the numbers must know."""

    name: str
    setting: str
    force: np.ndarray
    cpu_s: float
    wall_s: float
    rhs_evaluations: int
    steps: int
    note: str


def probe_slot(problem: ChainProblem, save: SaveAt) -> int:
    """The contact slot of the recorded probe: save holds one probe, one whole contact force
    (Chain.contact_probe)."""
    slots, weights = save.channels(problem.offset)
    if slots.shape[0] != 1 or np.count_nonzero(weights) != 1 or weights[0, 0] != 1.0:
        raise invalid("save.probes", save.names, "a peer records one probe: one contact force "
                                                "(Chain.contact_probe)")
    return int(slots[0, 0])


def output_samples(t_end: float, sample_interval: float) -> int:
    """Number of points of the grid t_j = j sample_interval up to t_end (as solve records)."""
    return time_grid(t_end, t_end, sample_interval)[2]


def absolute_tolerances(problem: ChainProblem, rtol: float) -> np.ndarray:
    """atol per state component (m for u, m/s for v) of both DOP853 peers:
    rtol x POSITION_SCALE for each u, rtol x max(max v0, VELOCITY_FLOOR) for each v."""
    nb = problem.n_bodies
    speed = max(float(problem.v0.max()), VELOCITY_FLOOR)
    return rtol * np.concatenate((np.full(nb, POSITION_SCALE), np.full(nb, speed)))


def check_conservative(problem: ChainProblem) -> None:
    """The peers integrate the conservative Hertz chain under constant loads only."""
    if problem.law != HERTZ or problem.onsite:
        raise invalid("chain.contact_law", problem.chain.law.name,
                      "the peers integrate the conservative Hertz law only")
    if problem.sched_t.size:
        raise invalid("chain.top_force", "ForceSchedule", "the peers take a constant top force only")


def probe_history(problem: ChainProblem, slot: int, u_above: np.ndarray, u_below: np.ndarray) -> np.ndarray:
    """F = A[s] max(d0[s] + u[s-1] - u[s], 0)^(3/2) (N) from the two displacements (m)."""
    d = np.maximum(problem.d0[slot] + u_above - u_below, 0.0)
    return problem.A[slot] * d * np.sqrt(d)


# --- scipy's DOP853 -------------------------------------------------------------------------

def scipy_dop853(problem: ChainProblem, save: SaveAt, t_end: float, rtol: float) -> PeerRun:
    """scipy.integrate.solve_ivp(method DOP853) on y = [u, v] with t_eval = the output grid,
    atol from absolute_tolerances; the right-hand side is vectorised numpy (a fresh array
    per call, as solve_ivp keeps references to what it returns). solve_ivp computes the
    dense output only for steps holding an output point and interpolates every component
    there; the probe is taken from the two displacements it needs after the timing."""
    from scipy.integrate import DOP853, solve_ivp

    check_conservative(problem)
    slot = probe_slot(problem, save)
    nb = problem.n_bodies
    A_mid, d0_mid, load_mid = problem.A[1:], problem.d0[1:], problem.load[1:nb]
    invm = problem.invm
    f = np.zeros(nb + 1)
    f[nb] = -problem.load[nb]

    def rhs(t, y):
        u = y[:nb]
        d = np.maximum(d0_mid + u[:-1] - u[1:], 0.0)
        f[1:nb] = A_mid * d * np.sqrt(d) - load_mid
        dy = np.empty(2 * nb)
        dy[:nb] = y[nb:]
        np.subtract(f[:-1], f[1:], out=dy[nb:])
        dy[nb:] *= invm
        return dy

    counted = {"steps": 0, "dense": 0}

    class CountedDOP853(DOP853):
        """scipy's DOP853, counting its accepted steps and its dense outputs."""

        def step(self):
            message = super().step()
            counted["steps"] += self.status != "failed"
            return message

        def dense_output(self):
            counted["dense"] += 1
            return super().dense_output()

    t_eval = np.arange(output_samples(t_end, save.sample_interval)) * save.sample_interval
    t_eval[-1] = min(t_eval[-1], t_end)
    y0 = np.concatenate((problem.u0, problem.v0))
    cpu0, wall0 = time.process_time(), time.perf_counter()
    r = solve_ivp(rhs, (0.0, t_end), y0, method=CountedDOP853, t_eval=t_eval, rtol=rtol,
                  atol=absolute_tolerances(problem, rtol))
    cpu, wall = time.process_time() - cpu0, time.perf_counter() - wall0
    if not r.success:
        raise RigError(f"scipy DOP853 failed: {r.message}")
    attempts = (r.nfev - 2 - 3 * counted["dense"]) // 12  # 12 evaluations per attempted step
    force = probe_history(problem, slot, r.y[slot - 1], r.y[slot])
    return PeerRun("scipy-DOP853", f"rtol={rtol:g}", force, cpu, wall, int(r.nfev), counted["steps"],
                   f"solve_ivp in process; {attempts - counted['steps']} rejected steps, "
                   f"{counted['dense']} dense outputs of all {2 * nb} components; times include "
                   f"interpolating every component at each output point")


# --- DOP853 compiled ------------------------------------------------------------------------

def numba_dop853(problem: ChainProblem, save: SaveAt, t_end: float, rtol: float) -> PeerRun:
    """DOP853 compiled with numba (rig/bench/kernels/dop853.py: Hairer's error estimate and
    step-size control, his starting step with scipy's norms), same tolerances as
    scipy_dop853; the probe from the 7th-order dense output of u[s-1] and u[s] only, whose
    three extra stages are computed only for steps that hold an output point. The kernel
    is compiled (or loaded from numba's cache) before the timing."""
    from rig.bench.kernels import dop853

    check_conservative(problem)
    slot = probe_slot(problem, save)
    nb = problem.n_bodies
    atol = absolute_tolerances(problem, rtol)
    n_out = output_samples(t_end, save.sample_interval)

    def run(t):
        y = np.concatenate((problem.u0, problem.v0))
        out = np.zeros(n_out)
        counts = np.zeros(5, np.int64)
        dop853.integrate(y, t, rtol, atol, problem.A, problem.d0, problem.load,
                         problem.invm, slot, save.sample_interval, out,
                         np.zeros((dop853.N_STAGES_EXTENDED, 2 * nb)), np.zeros(2 * nb),
                         np.zeros((2, 2 * nb)), np.zeros(nb + 1), counts)
        return out, counts

    run(min(t_end, save.sample_interval))  # compile or load, outside the timing
    cpu0, wall0 = time.process_time(), time.perf_counter()
    force, counts = run(t_end)
    cpu, wall = time.process_time() - cpu0, time.perf_counter() - wall0
    if counts[dop853.STATUS] != dop853.SUCCESS:
        raise RigError(f"numba DOP853: step size too small (rtol={rtol:g})")
    return PeerRun("numba-DOP853", f"rtol={rtol:g}", force, cpu, wall, int(counts[dop853.EVALUATIONS]),
                   int(counts[dop853.ACCEPTED]),
                   f"compiled, in process; {counts[dop853.REJECTED]} rejected steps, "
                   f"{counts[dop853.DENSE_STEPS]} steps with output points (3 extra stages each)")
