"""Many shots of one chain topology in one call of the batched kernel.

Every shot takes the same stepping, given by the caller (a study calibrates it once on its
nominal shot, rig/study/nominal.py), so a shot's result never depends on which other shots
share its batch: a shot solved alone with ``solve(problem, t_end, dt=stepping)`` gives the
same numbers to the last bit.
"""
from __future__ import annotations

import contextlib
import functools
import time
from contextvars import ContextVar
from dataclasses import dataclass

import numpy as np

from rig.errors import RigError, invalid
from rig.solver.kernels.ensemble import integrate_ensemble
from rig.solver.kernels.report import DIAGNOSTICS, ENERGY_ERROR, STATUS
from rig.solver.methods import DEFAULT_METHOD, Method
from rig.solver.methods import method as get_method
from rig.solver.problem import ChainProblem, ProblemArrays
from rig.solver.run import check_record, integrate_at, kernel_inputs, solution_of, time_grid
from rig.solver.saveat import SaveAt
from rig.solver.solution import KernelReport, Solution, SolverStats, Status
from rig.solver.stepsize import Stepping

ONE_SHOT_KERNEL: ContextVar[str] = ContextVar("one_shot_kernel", default="single")
"""The kernel that integrates one shot in this thread (``integrate_one``): "single"
(kernels/integrators.py) or "batched" (kernels/ensemble.py, as a batch of one; set by
``solved_as_batches``)."""


@dataclass(frozen=True, eq=False)
class EnsembleSolution:
    """records: (shots, probes, samples) (N), the probes in the SaveAt's order, each shot's
    record contiguous; forces: {probe: (shots, samples)}, views of it; diagnostics:
    (DIAGNOSTICS, shots), the kernel's report of every shot, each as a KernelReport in
    ``reports`` (built when first asked for: a study reads ``succeeded`` and
    ``energy_errors``, arrays, instead of 256 objects a batch)."""

    records: np.ndarray
    sample_interval: float
    dt: float
    steps: int
    wall_s: float
    method: str
    diagnostics: np.ndarray
    names: tuple

    @property
    def forces(self) -> dict:
        return {name: self.records[:, c] for c, name in enumerate(self.names)}

    @property
    def shots(self) -> int:
        return self.diagnostics.shape[1]

    @functools.cached_property
    def reports(self) -> tuple:
        """Each shot's KernelReport (energy and momentum errors, wall impulse, status)."""
        return tuple(KernelReport.of(self.diagnostics[:, j]) for j in range(self.shots))

    @functools.cached_property
    def succeeded(self) -> np.ndarray:
        """(shots,) bool: the shots whose status is Status.SUCCESS."""
        return self.diagnostics[STATUS] == Status.SUCCESS

    @property
    def energy_errors(self) -> np.ndarray:
        """(shots,): each shot's KernelReport.energy_error."""
        return self.diagnostics[ENERGY_ERROR]

    def stats(self, j: int, accuracy: float | None = None, estimate: float | None = None,
              basis: str = "study pilot") -> SolverStats:
        """Shot j's SolverStats (the batch's wall time shared out evenly); ``estimate``: the
        error estimate of the pilot that set the step, ``basis`` which pilot that was."""
        r = self.reports[j]
        m = get_method(self.method)
        return SolverStats(m.name, self.dt, self.steps, self.steps * m.force_evaluations,
                           self.wall_s / self.shots, r.energy_error, r.momentum_error,
                           r.wall_impulse_Ns, accuracy, estimate, basis if estimate is not None else "none",
                           dissipated_energy_J=r.dissipated_energy_J)


def solve_ensemble(problems, t_end: float, *, save: SaveAt, dt: float | Stepping,
                   method: str = DEFAULT_METHOD, width: int | None = None) -> EnsembleSolution:
    """Integrate every shot with the same stepping ``dt`` (a step in s, or a Stepping) to
    ``t_end`` (s), recording what ``save`` names for each shot. ``problems``: a list of
    ChainProblems of one layout, or their ProblemArrays. ``width``: shots per chunk
    (default: the batch shared out over numba's threads, 8 to 128: wider chunks spread each
    row's loop overhead over more shots, and 128 shots of a 53-body chain still fit the
    core's L2 cache). A shot that blows up is reported so (its report's status), not raised."""
    return _integrated(problems, t_end, save, dt, method, width)[0]


def integrate_one(problem: ChainProblem, t_end: float, save: SaveAt, m: Method, stepping: Stepping,
                  accuracy: float | None = None) -> Solution:
    """``run.integrate_at``'s Solution, from the kernel this thread's solves of one shot take
    (ONE_SHOT_KERNEL): the batched kernel as a batch of one where it can take the shot (no
    frames, no force schedule), else the single-shot kernel. The same bits either way."""
    if ONE_SHOT_KERNEL.get() == "batched" and save.frame_interval is None and not problem.sched_t.size:
        return batch_of_one(problem, t_end, save, m, stepping, accuracy)
    return integrate_at(problem, t_end, save, m, stepping, accuracy)


def batch_of_one(problem: ChainProblem, t_end: float, save: SaveAt, m: Method, stepping: Stepping,
                 accuracy: float | None = None) -> Solution:
    """``run.integrate_at``'s Solution of ``problem`` from the batched kernel, as a batch of
    one shot (a chunk of width 1; no frames, no force schedule): the same records and final
    state to the last bit (module doc); one that blows up returned so (its status), as
    integrate_at's. What a study's solves of one shot use (``solved_as_batches``)."""
    sol, u, v = _integrated([problem], t_end, save, stepping, m.name, 1)
    return solution_of(problem, save, sol.records[0], None, u[0, :, 0], v[0, :, 0], sol.reports[0], m, sol.dt,
                       sol.steps, sol.wall_s, accuracy)


@contextlib.contextmanager
def solved_as_batches():
    """Within it, this thread's solves of one shot that the batched kernel can take (no
    frames, no force schedule) run through it as a batch of one (``batch_of_one``; the same
    bits): a study, which compiles the batched kernel for its shots, then compiles (or
    loads) no single-shot kernel for its nominal solves."""
    token = ONE_SHOT_KERNEL.set("batched")
    try:
        yield
    finally:
        ONE_SHOT_KERNEL.reset(token)


def _integrated(problems, t_end: float, save: SaveAt, dt: float | Stepping, method: str,
                width: int | None) -> tuple:
    """(EnsembleSolution, u, v): solve_ensemble's, and the final displacements (m) and
    velocities (m/s) as (chunks, bodies, width)."""
    if not isinstance(problems, ProblemArrays):
        if not problems:
            raise invalid("problems", [], "at least one shot")
        p0 = problems[0]
        for p in problems:
            if (p.n_bodies, p.wall_slot, p.offset) != (p0.n_bodies, p0.wall_slot, p0.offset):
                raise RigError("an ensemble needs shots of one chain topology")
            if p.slip_speed != p0.slip_speed:
                raise RigError("an ensemble needs shots of one holder.slip_speed")
        problems = ProblemArrays.of(problems)
    p0 = problems.layout
    if p0.sched_t.size:
        raise RigError("the batched kernel takes constant loads only (no magnet schedule)")
    m = get_method(method)
    stepping = dt if isinstance(dt, Stepping) else Stepping(dt)
    if not (t_end > 0 and stepping.dt > 0):
        raise invalid("t_end/dt", (t_end, stepping.dt), "both > 0 s")
    n_steps, step, n_out = time_grid(t_end, min(stepping.dt, t_end), save.sample_interval)
    check_record(p0, save, n_out * problems.shots, 0)
    n = problems.shots
    if width is None:
        import numba

        width = int(min(128, max(8, -(-n // numba.get_num_threads()))))
    n_chunks = -(-n // width)
    fill = np.concatenate((np.arange(n), np.full(n_chunks * width - n, n - 1)))  # the last chunk filled up

    def chunked(name):  # (shots, ...) -> a view (chunks, ..., width)
        a = getattr(problems, name)
        a = (a[fill] if fill.size > n else a).reshape((n_chunks, width) + a.shape[1:])
        return a.transpose(0, *range(2, a.ndim), 1)

    def stack(name):  # each chunk C-contiguous, a copy (the kernel integrates u and v in place)
        return np.array(chunked(name), order="C")

    def rows(names):  # (chunks, rows, ..., width), in one copy
        parts = [chunked(k) for k in names]
        out = np.empty((n_chunks, len(parts)) + parts[0].shape[1:])
        for r, part in enumerate(parts):
            out[:, r] = part
        return out

    out = np.empty((n, len(save.names), n_out))  # the kernel writes every sample of every shot
    diag = np.zeros((n_chunks, DIAGNOSTICS, width))
    u, v = stack("u0"), stack("v0")
    k = kernel_inputs(problems, stack, rows, m, stepping, step, n_steps, save, out, np.zeros((0, p0.n_bodies)), 1.0)
    t0 = time.perf_counter()
    integrate_ensemble(u, v, k.chain, k.contacts, k.holder, k.method, k.record, k.checks, diag)
    wall = time.perf_counter() - t0
    diag = np.ascontiguousarray(np.moveaxis(diag, 0, -2).reshape(DIAGNOSTICS, n_chunks * width)[:, :n])
    return EnsembleSolution(out, save.sample_interval, step, n_steps, wall, m.name, diag, save.names), u, v
