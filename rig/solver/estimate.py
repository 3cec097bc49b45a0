"""How big and how long a solve will be, before it runs: memory from the output grid
(recorded channels x samples), time from the step rule (steps x (bodies x a measured cost
per body-step + a step's own cost)). The command line refuses a run beyond LIMIT_BYTES or LIMIT_SECONDS unless
the user confirms it (``--allow-large``)."""
from __future__ import annotations

import math
from dataclasses import dataclass

from rig.errors import RigError
from rig.solver.control import WORK_BUDGET
from rig.solver.methods import method as get_method
from rig.solver.problem import ChainProblem
from rig.solver.run import time_grid
from rig.solver.stepsize import checked_accuracy, default_step, viscous_rate

NS_PER_BODY_STEP = 7.0  # srkn6b's whole step, one core: 6 force evaluations of about 1.2 ns per body
NS_PER_BODY_SUBSTEP = 10.0  # a substep of the viscous flow, a body (8 to 23 ns measured, Kuwabara-Kono, 54 bodies)
NS_PER_STEP = 2000.0  # a step's own cost whatever the chain: the head's substeps, recording, the checks
# (1.4 to 2.7 us a step beside the bodies' on ptfe52_gravity, ptfe52_magnetic and steel21_gravity; the
# bodies' 7 ns alone had their solves 4 to 18 times dearer than estimated)
CONTROL_WORK = 6.0  # a controlled solve in solves at its final step: about 2 tries, each with a companion at dt/2
COPIES = 4  # the output grid, the truth, the instruments' inputs and their conditioning
LIMIT_BYTES = 2e9
LIMIT_SECONDS = 120.0
NOTICE_SECONDS = 10.0  # a run longer than this is announced with its estimate before it starts


@dataclass(frozen=True)
class RunEstimate:
    """A run's size: bytes of arrays it holds at once, seconds of solving, and what they
    come from (steps of the solver, moving bodies, output samples per channel)."""

    bytes: float
    seconds: float
    steps: int
    bodies: int
    samples: int
    most_seconds: float = math.nan  # the bound: the accuracy control's work budget spent (nan: seconds)
    substeps: int = 0  # the viscous flow's substeps a step (stepsize.viscous_rate; 0: no viscous contacts)

    @property
    def bound_seconds(self) -> float:
        """The most seconds of solving the run may take: the accuracy control gives up
        (rig/solver/control.py, WORK_BUDGET) before it spends more."""
        return self.seconds if math.isnan(self.most_seconds) else self.most_seconds

    def times(self, runs: int, kept: int) -> RunEstimate:
        """``runs`` such solves one after another, ``kept`` of them held in memory at once."""
        return RunEstimate(self.bytes * kept, self.seconds * runs, self.steps, self.bodies, self.samples,
                           self.most_seconds * runs, self.substeps)

    @property
    def large(self) -> bool:
        return self.bytes > LIMIT_BYTES or self.seconds > LIMIT_SECONDS

    def describe(self) -> str:
        bound = f", at most {self.bound_seconds:.3g} s" if self.bound_seconds > self.seconds else ""
        flow = f" and {self.substeps} substeps of the viscous flow each" if self.substeps > 2 else ""
        return (f"about {self.bytes / 1e9:.3g} GB and {self.seconds:.3g} s of solving{bound} "
                f"({self.steps} steps x {self.bodies} bodies{flow}, {self.samples} samples per channel)")

    def refuse_unless(self, allowed: bool, what: str):
        """RigError naming the estimate and the confirming flag, if large and not allowed."""
        if self.large and not allowed:
            beyond = [f"{LIMIT_BYTES / 1e9:g} GB" if self.bytes > LIMIT_BYTES else "",
                      f"{LIMIT_SECONDS:g} s" if self.seconds > LIMIT_SECONDS else ""]
            limits = " and ".join(b for b in beyond if b)
            raise RigError(f"{what} needs {self.describe()}, beyond the limit{'s' if all(beyond) else ''} of "
                           f"{limits}; add --allow-large to run it anyway")


def estimate_solve(problem: ChainProblem, t_end: float, channels: int, sample_interval: float,
                   method: str, accuracy: float | None = None, controlled: bool = True) -> RunEstimate:
    """The estimate of ``solve(problem, t_end, ...)`` recording ``channels`` channels every
    ``sample_interval`` (s), with the step the solver would start from for ``accuracy``
    (the accuracy control's tries and companions counted as CONTROL_WORK solves, and at
    most its WORK_BUDGET; one solve where ``controlled`` is False: a study's shots reuse
    its pilot's step)."""
    stepping = default_step(problem, get_method(method), checked_accuracy(accuracy), t_end)
    dt = min(stepping.dt, t_end)
    steps, _, samples = time_grid(t_end, dt, sample_interval)  # the grid solve takes
    rate = viscous_rate(problem)  # the viscous flow: two half steps a step, each of ceil(dt/2 x rate) substeps
    flow = 2 * max(1, math.ceil(0.5 * dt * rate)) if rate > 0 else 0
    per_body = NS_PER_BODY_STEP + flow * NS_PER_BODY_SUBSTEP
    one = steps * (problem.moving_bodies * per_body + NS_PER_STEP) * 1e-9  # s
    return RunEstimate(8.0 * samples * max(channels, 1) * COPIES, one * (CONTROL_WORK if controlled else 1.0),
                       steps, problem.moving_bodies, samples, one * WORK_BUDGET if controlled else math.nan, flow)
