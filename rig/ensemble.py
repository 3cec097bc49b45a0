"""Many shots of one chain topology in one call of the batched kernel.

The step is the smallest that any shot's accuracy target (or stability) asks for, so a
shot's result never depends on which other shots share its batch: a shot solved alone with
``solve(problem, t_end, dt=step)`` gives the same numbers to the last bit.
"""
from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from ._kernels.ensemble import integrate_ensemble
from .errors import RigError, invalid
from .methods import DEFAULT_METHOD, method as get_method
from .solve import MAX_CHECKS, time_grid
from .stepsize import DEFAULT_ACCURACY, Stepping, default_step, single_rate_step


@dataclass(frozen=True, eq=False)
class EnsembleSolution:
    """forces: {probe: (shots, samples) array (N), each shot's row contiguous}; diag: (6, shots)
    as SolverStats fields (energy error, momentum error, wall impulse, status, steps, end time)."""

    forces: dict
    sample_interval: float
    dt: float
    steps: int
    wall_s: float
    diag: np.ndarray

    @property
    def shots(self) -> int:
        return self.diag.shape[1]


def ensemble_step(problems, t_end: float, method=DEFAULT_METHOD, accuracy=None) -> Stepping:
    """The common stepping of a batch: the smallest step (and substep) any of its shots
    needs; multirate only when every shot has the same head, else the single-rate step."""
    m = get_method(method)
    acc = DEFAULT_ACCURACY if accuracy is None else accuracy
    if not problems:
        raise invalid("problems", [], "at least one shot")
    own = [default_step(p, m, acc) for p in problems]
    if own[0].head and all(s.head == own[0].head for s in own):
        return Stepping(min(s.dt for s in own), own[0].head, min(s.inner_dt for s in own))
    return Stepping(min(single_rate_step(p, m, acc) for p in problems))


def solve_ensemble(problems: list, t_end: float, *, dt: float | Stepping, method: str = DEFAULT_METHOD,
                   width: int | None = None) -> EnsembleSolution:
    """Integrate every problem with the same stepping ``dt`` (a step in s, or a Stepping)
    to ``t_end`` (s). ``width``: shots per chunk (default: the batch shared out over
    numba's threads, 8 to 128: wider chunks spread each row's loop overhead over more
    shots, and 128 shots of a 53-body chain still fit the core's L2 cache)."""
    if not problems:
        raise invalid("problems", [], "at least one shot")
    m = get_method(method)
    p0 = problems[0]
    for p in problems:
        if (p.n_bodies, p.wall_slot, p.offset, p.ch_names) != (p0.n_bodies, p0.wall_slot, p0.offset, p0.ch_names) \
                or not np.array_equal(p.ch_slot, p0.ch_slot) or not np.array_equal(p.ch_weight, p0.ch_weight):
            raise RigError("an ensemble needs shots of one chain topology and one set of probes")
        if p.sched_t.size or p.chain.law.dissipative:
            raise RigError("the batched kernel takes conservative chains with constant loads only")
    stepping = dt if isinstance(dt, Stepping) else Stepping(dt)
    if not (t_end > 0 and stepping.dt > 0):
        raise invalid("t_end/dt", (t_end, stepping.dt), "both > 0 s")
    rec = p0.record
    n_steps, step, n_out = time_grid(t_end, min(stepping.dt, t_end), rec.sample_interval)
    sub = stepping.substeps(step, m.drifts)
    n = len(problems)
    if width is None:
        import numba

        width = int(min(128, max(8, -(-n // numba.get_num_threads()))))
    n_chunks = -(-n // width)
    padded = problems + [problems[-1]] * (n_chunks * width - n)  # the last chunk filled up

    def blocks(values):  # -> (chunks, ..., width), each chunk C-contiguous
        a = np.stack(values, axis=-1)
        return np.ascontiguousarray(np.moveaxis(a.reshape(a.shape[:-1] + (n_chunks, width)), -2, 0))

    stack = lambda name: blocks([getattr(p, name) for p in padded])  # noqa: E731
    out = np.zeros((n_chunks, width, len(p0.ch_names), n_out))
    diag = np.zeros((n_chunks, 6, width))
    u, v = stack("u0"), stack("v0")
    t0 = time.perf_counter()
    integrate_ensemble(u, v, stack("mass"), stack("invm"), stack("bias"), stack("load"), stack("A"),
                       stack("d0"), np.array(m.drifts), np.array(m.kicks), step, n_steps, stepping.head, sub,
                       p0.ch_slot, p0.ch_weight, rec.sample_interval, out,
                       max(1, n_steps // MAX_CHECKS), stack("d_limit"), p0.wall_slot,
                       blocks([p.energy_scale for p in padded]), blocks([p.momentum_scale for p in padded]),
                       diag)
    wall = time.perf_counter() - t0
    out = out.reshape(n_chunks * width, len(p0.ch_names), n_out)[:n]  # a view: (shots, channels, samples)
    diag = np.moveaxis(diag, 0, -2).reshape(6, n_chunks * width)[:, :n]
    if np.any(diag[3] != 0):
        bad = np.flatnonzero(diag[3] != 0)
        raise RigError(f"the integration became unstable for shot(s) {bad.tolist()[:10]} "
                       f"(dt = {step:.4g} s): use a tighter accuracy")
    return EnsembleSolution({name: out[:, c] for c, name in enumerate(p0.ch_names)}, rec.sample_interval,
                            step, n_steps, wall, diag)
