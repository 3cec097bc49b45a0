"""One integration of a problem at a given stepping: the output grid, the kernel call and
its report turned into a Solution (the accuracy control of rig/solver/control.py and
``solve`` are built on it)."""
from __future__ import annotations

import math
import os
import time
from collections.abc import Callable
from dataclasses import replace
from typing import NamedTuple

import numpy as np

from numerics.dispatcher import Constant
from rig.errors import RigError, invalid
from rig.model.laws.thornton import STATE_ROWS
from rig.solver.kernels import bundles
from rig.solver.kernels.integrators import integrate
from rig.solver.kernels.layout import working_arrays
from rig.solver.kernels.report import DIAGNOSTICS
from rig.solver.methods import Method
from rig.solver.problem import CONTACT_ROWS, ChainProblem, ProblemArrays
from rig.solver.saveat import SaveAt
from rig.solver.solution import KernelReport, Solution, SolverStats, Status
from rig.solver.stepsize import Stepping, viscous_rate

MAX_CHECKS = 50  # energy / momentum / blow-up checks per solve (each one O(N))
CHECK_SPACING = 4  # steps at least between two checks: a check costs about half a step


def check_interval(n_steps: int) -> int:
    """Steps between two checks of a solve of n_steps (the last step is always checked)."""
    return max(CHECK_SPACING, n_steps // MAX_CHECKS)


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


def physical_memory() -> int:
    """This machine's memory (bytes): the most a run may hold."""
    return os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")


def check_record(problem: ChainProblem, save: SaveAt, n_out: int, n_frames: int) -> None:
    """Refuse, naming the field, a probe of a contact this chain does not have (its slot
    would be read outside the kernels' arrays) and a record larger than this machine's
    memory (n_out samples per channel, n_frames frames of every body)."""
    lo, hi = 1 - problem.offset, problem.n_bodies - 1 - problem.offset
    for name, probe in save.probes.items():
        for k, w in zip(probe.contacts, probe.weights):
            if w != 0.0 and not lo <= k <= hi:
                raise invalid(f"save[{name!r}]", f"contact {k}", f"contacts {lo}..{hi} of this chain")
    need = 8.0 * (len(save.names) * n_out + n_frames * problem.n_bodies)
    have = physical_memory()
    if need > have:
        raise RigError(f"the record would take {need / 1e9:.3g} GB ({n_out} samples per channel, {n_frames} "
                       f"frames), more than this machine's {have / 1e9:.3g} GB: give save a longer "
                       f"sample_interval or frame_interval, or a shorter t_end")


class KernelInputs(NamedTuple):
    """What an entry kernel takes besides the state it renews (u, v; the single-shot
    kernel's f and front too) and its report (diag): the bundles of
    rig/solver/kernels/bundles.py, by name, in the order integrators.integrate takes them
    (the batched kernel takes every one but the schedule)."""

    chain: bundles.ChainArrays
    contacts: bundles.Contacts
    holder: bundles.Holder
    method: bundles.Method
    schedule: bundles.Schedule
    record: bundles.Record
    checks: bundles.Checks


def stacked(take: Callable[[str], np.ndarray], axis: int) -> Callable[[tuple], np.ndarray]:
    """kernel_inputs' ``rows`` from its ``take``: the fields' arrays stacked on ``axis``."""
    def rows(names):
        return np.ascontiguousarray(np.stack([take(k) for k in names], axis=axis))
    return rows


def kernel_inputs(problems: ChainProblem | ProblemArrays, take: Callable[[str], np.ndarray],
                  rows: Callable[[tuple], np.ndarray], m: Method, stepping: Stepping, step: float, n_steps: int,
                  save: SaveAt, out: np.ndarray, frames: np.ndarray, frame_dt: float) -> KernelInputs:
    """The bundles of one kernel call, for one shot (``integrate_at``) or a batch
    (rig.solver.ensemble): ``take(name)`` gives the kernel's array of the ChainProblem
    field ``name`` (a shot's as placed by layout.working_arrays; a batch's (chunks, ...,
    width)), ``rows(names)`` the per-body rows of several fields stacked (con, state,
    onsite: a shot's (rows, bodies), a batch's (chunks, rows, bodies, width)); n_steps
    steps of ``step`` (s) of method ``m`` with ``stepping``'s head; ``out`` and ``frames``
    (every frame_dt s) receive the record of ``save``."""
    layout = problems.layout if isinstance(problems, ProblemArrays) else problems
    ch_slot, ch_weight = save.channels(layout.offset)
    con, onsite = rows(CONTACT_ROWS), rows(("drag", "friction"))
    flows = Constant(int(any(np.any(getattr(problems, k) != 0.0) for k in ("damping", "dashpot", "drag", "friction"))))
    return KernelInputs(
        bundles.ChainArrays(*(take(k) for k in bundles.ChainArrays._fields)),
        bundles.Contacts(Constant(problems.law), con, rows(STATE_ROWS)),
        bundles.Holder(onsite, layout.slip_speed, viscous_rate(problems), flows),
        bundles.Method(np.array(m.drifts), np.array(m.kicks), step, n_steps, stepping.head,
                       stepping.substeps(step, m.drifts), Constant(int(stepping.head > 0))),
        bundles.Schedule(layout.sched_body, layout.sched_t, layout.sched_f),
        bundles.Record(ch_slot, ch_weight, save.sample_interval, out, frame_dt, frames),
        bundles.Checks(check_interval(n_steps), take("energy_scale"), take("momentum_scale"), layout.wall_slot))


class Unstable(RigError):
    """An integration that blew up (an overlap beyond half a bead radius): the step is too
    large. Carries the stepping that failed. What the solve functions raise from an
    UNSTABLE Solution (``Unstable.check``)."""

    def __init__(self, message: str, stepping: Stepping):
        super().__init__(message)
        self.stepping = stepping

    @classmethod
    def check(cls, sol: Solution, stepping: Stepping) -> Solution:
        """``sol`` where it did not blow up; else Unstable with its message."""
        if sol.status is Status.UNSTABLE:
            raise cls(sol.message, stepping)
        return sol


def integrate_at(problem: ChainProblem, t_end: float, save: SaveAt, m: Method, stepping: Stepping,
                 accuracy: float | None = None, front: bool = True) -> Solution:
    """Integrate ``problem`` from the impact to t_end (s) with ``stepping`` (whole steps
    ending at t_end), recording what ``save`` names. Raises Unstable if it blows up.
    ``front``: integrate only the bodies the pulse has reached, those still at rest bit for
    bit being left as they are (False: every body every step; the same bits, for tests)."""
    n_steps, step, n_out = time_grid(t_end, min(stepping.dt, t_end), save.sample_interval)
    if save.frame_interval is not None:
        n_frames = int(math.floor(t_end / save.frame_interval * (1 + 1e-12))) + 1
        frame_dt = save.frame_interval
    else:
        n_frames, frame_dt = 0, 1.0
    check_record(problem, save, n_out, n_frames)
    out = np.zeros((len(save.names), n_out))
    frames = np.zeros((n_frames, problem.n_bodies))
    invm, A, d0, load, u, v, f = working_arrays(problem.invm, problem.A, problem.d0, problem.load, problem.u0,
                                                problem.v0, np.zeros(problem.n_bodies + 1))
    diag = np.zeros(DIAGNOSTICS)
    placed = {"invm": invm, "A": A, "d0": d0, "load": load}

    def take(name):
        return placed[name] if name in placed else getattr(problem, name)

    k = kernel_inputs(problem, take, stacked(take, 0), m, stepping, step, n_steps, save, out, frames, frame_dt)
    warm = k._replace(contacts=k.contacts._replace(state=problem.memory()), method=k.method._replace(n_steps=0))
    integrate(u.copy(), v.copy(), f, *warm, diag, front)  # load the compiled kernel
    t0 = time.perf_counter()
    integrate(u, v, f, *k, diag, front)
    wall = time.perf_counter() - t0
    shown = slice(0, problem.offset + problem.chain.n_beads)  # the striker and the beads (not a wall's plate)
    frames_abs = frames[:, shown] + frame_origin(problem.chain) if n_frames else None
    sol = solution_of(problem, save, out, frames_abs, u, v, KernelReport.of(diag), m, step, n_steps, wall, accuracy)
    return replace(sol, memory=k.contacts.state)  # the kernel renewed it in place: the memory at the end


def solution_of(problem: ChainProblem, save: SaveAt, out: np.ndarray, frames: np.ndarray | None, u: np.ndarray,
                v: np.ndarray, report: KernelReport, m: Method, step: float, n_steps: int, wall: float,
                accuracy: float | None) -> Solution:
    """The Solution of one integration of ``problem``: its records ``out`` (channels,
    samples; N) of ``save``, its frames (m; None: none), the final displacements ``u`` (m)
    and velocities ``v`` (m/s) of every body, and the kernel's report of ``n_steps`` steps of
    ``step`` (s) of method ``m``, which took ``wall`` s."""
    detail = "" if report.status is Status.SUCCESS else \
        f" (near t = {report.end_time_s:.4g} s, dt = {step:.4g} s, method {m.name})"
    stats = SolverStats(m.name, step, n_steps, n_steps * m.force_evaluations, wall,
                        report.energy_error, report.momentum_error, report.wall_impulse_Ns, accuracy,
                        dissipated_energy_J=report.dissipated_energy_J, bodies_stepped=report.bodies_stepped)
    moving = slice(0, problem.n_bodies - (1 if problem.wall_slot else 0))
    return Solution(dict(zip(save.names, out)), save.sample_interval, frames,
                    save.frame_interval if frames is not None else None, u[moving].copy(), v[moving].copy(), stats,
                    problem, report.status, detail)
