"""What a run will cost, estimated before it runs: memory from the output grid, CPU time
from the step count.

A shot records every probe the instruments need (two contacts per gauge bead and the wall)
at the solver's sample interval, and each scope input passes through a few float64 arrays of
that length (gauge signal, RC filter, noise, bandwidth): about

    memory = samples x 8 B x (probes + ARRAYS_PER_CHANNEL x channels)

The solver takes n_steps = duration / dt steps (dt from the accuracy rule, rig.solver.
stepsize) of ``force_evaluations`` passes over the moving bodies each, at about
NS_PER_BODY_EVALUATION ns per body and pass plus a fixed PASS_OVERHEAD_S, measured on
this project's 2-core reference machine (docs/solver.md) and rounded up:

    cpu = n_steps x evaluations x (bodies x NS_PER_BODY_EVALUATION + PASS_OVERHEAD_S)

Runs above LIMIT_BYTES or LIMIT_SECONDS are refused unless the user confirms
(--allow-large): the estimate and the limit are named in the one-line refusal.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from rig.errors import RigError

LIMIT_BYTES = 2 * 1024**3
LIMIT_SECONDS = 120.0
NS_PER_BODY_EVALUATION = 5e-9
PASS_OVERHEAD_S = 1.5e-6
ARRAYS_PER_CHANNEL = 4


@dataclass(frozen=True)
class Budget:
    """Estimated cost of a run: peak memory (bytes), CPU time (s) and what they come from."""

    memory_bytes: float
    cpu_s: float
    what: str

    def times(self, n: int, in_memory: int | None = None) -> Budget:
        """n such runs, one after another, of which ``in_memory`` (default: all) are held at once."""
        return Budget(self.memory_bytes * (n if in_memory is None else in_memory), self.cpu_s * n,
                      f"{n} x ({self.what})")

    def check(self, allowed: bool) -> Budget:
        """Refuse in one line a run over the limits unless ``allowed``."""
        if allowed or (self.memory_bytes <= LIMIT_BYTES and self.cpu_s <= LIMIT_SECONDS):
            return self
        raise RigError(f"this run would need about {_bytes(self.memory_bytes)} of memory and "
                       f"{_seconds(self.cpu_s)} of CPU ({self.what}); without --allow-large the limits are "
                       f"{_bytes(LIMIT_BYTES)} and {_seconds(LIMIT_SECONDS)}")

    def note(self) -> str:
        return f"about {_bytes(self.memory_bytes)} and {_seconds(self.cpu_s)} of CPU ({self.what})"


def shot_budget(rig) -> Budget:
    """The cost of one shot of an assembled Rig (rig.experiment.shot), nothing solved."""
    from rig.solver.methods import method as get_method
    from rig.solver.problem import ChainProblem
    from rig.solver.solve import time_grid
    from rig.solver.stepsize import DEFAULT_ACCURACY, default_step

    s = rig.solver
    method = get_method(s.method)
    problem = ChainProblem.from_chain(rig.chain)
    stepping = default_step(problem, method, s.accuracy or DEFAULT_ACCURACY)
    steps, _, samples = time_grid(s.duration, stepping.dt, s.sample_interval)
    probes = len(rig.save_at().probes)
    channels = len(rig.gauges) + (rig.wall_sensor is not None)
    memory = samples * 8.0 * (probes + ARRAYS_PER_CHANNEL * channels)
    bodies = problem.moving_bodies
    cpu = steps * method.force_evaluations * (bodies * NS_PER_BODY_EVALUATION + PASS_OVERHEAD_S)
    return Budget(memory, cpu, f"{steps:.3g} steps x {bodies} bodies, {samples:.3g} samples x {probes} probes")


def _bytes(n: float) -> str:
    for unit, size in (("GiB", 1024**3), ("MiB", 1024**2), ("KiB", 1024)):
        if n >= size:
            return f"{n / size:.3g} {unit}"
    return f"{n:.0f} B"


def _seconds(s: float) -> str:
    if s >= 3600:
        return f"{s / 3600:.3g} h"
    if s >= 60:
        return f"{s / 60:.3g} min"
    return f"{s:.2g} s" if s >= 0.01 or s == 0 else f"{s * 1e3:.2g} ms" if math.isfinite(s) else "inf s"
