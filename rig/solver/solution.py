"""Solution: what a solve recorded, and how the solve went."""
from __future__ import annotations

import enum
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from rig.model.contact import hertz_energy
from rig.solver.kernels import report as slot

if TYPE_CHECKING:
    from rig.solver.problem import ChainProblem


class Status(enum.IntEnum):
    """How a solve ended (like scipy's OdeResult.status). SUCCESS and UNSTABLE are what the
    kernels write in their report's STATUS slot; ACCURACY_NOT_REACHED is the accuracy
    control's (rig/solver/control.py): its bound on the work ended it above the accuracy."""

    SUCCESS = 0
    UNSTABLE = 1  # an overlap grew beyond half a bead radius: the step is too large
    ACCURACY_NOT_REACHED = 2  # the most accurate try returned, its error estimate above the accuracy

    @property
    def message(self) -> str:
        return _STATUS_MESSAGES[self]


_STATUS_MESSAGES = {
    Status.SUCCESS: "the integration reached the end time",
    Status.UNSTABLE: "the integration became unstable (an overlap grew beyond half a bead radius); use a smaller "
                     "dt or a tighter accuracy",
    Status.ACCURACY_NOT_REACHED: "the integration reached the end time, its error estimate above the accuracy"}


@dataclass(frozen=True)
class KernelReport:
    """What an integration kernel reports in its float64[DIAGNOSTICS] diagnostics array,
    by name (the slots of rig/solver/kernels/report.py)."""

    energy_error: float
    momentum_error: float
    wall_impulse_Ns: float
    status: Status
    steps: int
    end_time_s: float
    dissipated_energy_J: float
    bodies_stepped: float  # the bodies a step integrated, on average (the front; all of them at most)

    @classmethod
    def of(cls, diag) -> KernelReport:
        """The report in a diagnostics array (a shot's column of a batch's)."""
        steps = int(diag[slot.STEPS])
        return cls(float(diag[slot.ENERGY_ERROR]), float(diag[slot.MOMENTUM_ERROR]), float(diag[slot.WALL_IMPULSE]),
                   Status(int(diag[slot.STATUS])), steps, float(diag[slot.END_TIME]), float(diag[slot.DISSIPATED]),
                   float(diag[slot.BODIES_STEPPED]) / max(steps, 1))


@dataclass(frozen=True)
class SolverStats:
    """Diagnostics of one solve.

    energy_error: max |E(t) + dissipated(t) - E(0)| / E_ref over the checks (E_ref: the
    striker's kinetic energy, or the static elastic energy without a striker; dissipated:
    what the contacts' viscous terms and the holder's drag and friction took). momentum_error:
    max |P(t) - P(0) - external impulse| / P_ref (P_ref: the striker's momentum), external
    impulse = constant loads x t + scheduled force impulse - wall impulse + the holder's.
    dissipated_energy_J: the energy dissipation took over the whole solve (J).
    bodies_stepped: the bodies a step integrated, on average: the beads the pulse has not
    reached are at rest and left as they are (rig/solver/kernels/integrators.py), so this is
    less than the chain's bodies where the record ends before the pulse fills the chain
    (0 for a batch's shots, whose chunks of shots share one front).
    error_estimate: the a-posteriori estimate of the largest error of any recorded force,
    relative to its dynamic peak (``relative_error``), over the whole record; None where
    nothing was recorded. estimate_basis: how it was obtained ("companion at dt/2": a
    second solve at half the step, Richardson; "study pilot": the nominal shot of a study;
    "fit pilot": a fit's start values, rig.fit.evaluate).
    attempts: solves the accuracy control ran (rig/solver/control.py). wall_s: the kernel's
    wall time of the solve returned; cpu_s: the process CPU time of everything solve did,
    its attempts and companions included.
    """

    method: str
    dt_s: float
    steps: int
    force_evaluations: int
    wall_s: float
    energy_error: float
    momentum_error: float
    wall_impulse_Ns: float
    accuracy: float | None
    error_estimate: float | None = None
    estimate_basis: str = "none"
    attempts: int = 1
    cpu_s: float = 0.0
    dissipated_energy_J: float = 0.0
    bodies_stepped: float = 0.0

    def as_dict(self) -> dict:
        return dict(self.__dict__)


STATIC = 1e-9  # a record whose forces move by less than this fraction of their size holds no pulse


def relative_error(forces: dict, reference: dict) -> float:
    """The largest error of any channel of ``forces`` against ``reference`` ({name: array},
    the same grid), relative to that channel's dynamic peak max |F_ref(t) - F_ref(0)|:
    what the accuracy setting bounds. A channel whose dynamic peak is below 1e-6 of the
    largest one (the pulse never reached it) is measured against that largest one. Where
    no channel moves by more than STATIC of the largest force recorded (the striker has not
    landed yet), the differences are rounding (float64 summed over a million operations
    drifts by about 1e-10) and are measured against STATIC x that force."""
    peaks = {k: float(np.max(np.abs(r - r[0]))) if r.size else 0.0 for k, r in reference.items()}
    top = max(peaks.values(), default=0.0)
    static = STATIC * max((float(np.max(np.abs(r))) for r in reference.values() if r.size), default=0.0)
    if top <= static:
        peaks, top = dict.fromkeys(peaks, static), static
    if top == 0.0:
        return 0.0
    return max(float(np.max(np.abs(forces[k] - r))) / max(peaks[k], 1e-6 * top)
               for k, r in reference.items() if r.size)


@dataclass(frozen=True, eq=False)
class Solution:
    """Recorded forces (N) on the grid t = j * sample_interval, j = 0..n-1 (t = 0: impact).

    frames: positions (m, down from bead 0's equilibrium centre) of the striker (if any)
    and the beads at t = j * frame_interval, only when frames were asked for.
    final_u, final_v: each body's displacement (m) and velocity (m/s) at the end.
    memory: the contacts' memory at the end (rig.model.laws.thornton.STATE_ROWS, the
    problem's slots), of a single shot's solve (None from a batch): what the chain keeps
    for its next shot (Chain.after_shot).
    status: how the solve ended (Status); detail: what it adds to the status's message for
    this solve (where and at what step it blew up, how far the control got), "" where
    nothing. A solve that is not SUCCESS returns its record as far as it went.
    """

    forces: dict
    sample_interval: float
    frames: np.ndarray | None
    frame_interval: float | None
    final_u: np.ndarray
    final_v: np.ndarray
    stats: SolverStats
    problem: ChainProblem
    status: Status = Status.SUCCESS
    detail: str = ""
    memory: np.ndarray | None = None  # the contacts' memory at the end (STATE_ROWS, the problem's slots); one shot

    @property
    def message(self) -> str:
        """How the solve ended, in one line: the status's message and this solve's detail."""
        return f"{self.status.message}{self.detail}"

    @property
    def success(self) -> bool:
        return self.status is Status.SUCCESS

    @property
    def time(self) -> np.ndarray:
        n = len(next(iter(self.forces.values()))) if self.forces else 0
        return np.arange(n) * self.sample_interval

    def final_body_energies(self) -> np.ndarray:
        """Energy (J) of each moving body at the end: kinetic plus half of the elastic
        energy of each of its contacts (constant-load potentials excluded)."""
        p = self.problem
        n = self.final_u.shape[0]
        u = np.zeros(p.n_bodies)
        u[:n] = self.final_u
        d = np.maximum(p.d0[1:] + u[:-1] - u[1:], 0.0)
        contact = np.concatenate(([0.0], hertz_energy(p.A[1:], d, p.expo[1:]), [0.0]))
        e = 0.5 * p.mass * np.pad(self.final_v, (0, p.n_bodies - n)) ** 2
        e += 0.5 * (contact[:-1] + contact[1:])
        return e[:n]

    @property
    def recorded_bytes(self) -> int:
        """Bytes held by the recorded channels and frames (what 'record only what is asked' buys)."""
        n = sum(a.nbytes for a in self.forces.values())
        return n + (self.frames.nbytes if self.frames is not None else 0)
