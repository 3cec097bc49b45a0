"""Choosing the time step: contact time scale, accuracy target, stability limit.

Contact time scale (Nesterenko 2001; the duration of a Hertz collision scales with it):

    tau = min over contacts of  (m / (A v^(1/2)))^(2/5)     impact at speed v
                        and     sqrt(m / k0),  k0 = (3/2) A^(2/3) F0^(1/3)   precompressed

with m the reduced mass of the two bodies. A pulse that crosses N contacts accumulates a
phase error ~ N (dt/tau)^p, so for a target relative force error ``accuracy``

    dt = tau * (accuracy / (C N))^(1/p)

with the method's contact order p and error constant C (calibrated on the solver
benchmark, see docs/solver.md). The step is also kept below half the linear stability
limit omega_max dt < S (S from the method's coefficients), with omega_max bounded by
Gershgorin's theorem on the chain linearised at an upper estimate of the peak forces.

Multirate head. A striker much stiffer against its first bead than the chain's own
contacts (alumina on the steel magnetic bead: tau 3.7 us against 19 us in the PTFE) would
set the step of the whole chain. When the first ``head`` contacts are that stiff (tau below
HEAD_RATIO x the median tau), they are split off (r-RESPA / impulse multiple time
stepping, Tuckerman, Berne & Martyna 1992): each drift of the method becomes the flow of
kinetic energy + the head's contacts, integrated by substeps of the same method of at
most ``inner_dt``; the method's kicks carry the other contacts. The substep is the step
the single-rate rule above gives for the whole chain; the outer step follows the slow
contacts (accuracy and stability as above, and at most the head's smallest tau, which
keeps it below half the head's collision time, away from MTS resonances).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rig.errors import invalid
from rig.memo import computed_once
from rig.model.contact import contact_stiffness
from rig.solver.methods import Method

DEFAULT_ACCURACY = 1e-4
HEAD_RATIO = 0.5   # a leading contact with tau < HEAD_RATIO x median tau is integrated apart
MAX_HEAD = 3       # at most this many leading contacts form the head
HEAD_SUBSTEP = 0.5  # the head's substep, as a fraction of the single-rate step


@dataclass(frozen=True)
class Stepping:
    """How a solve steps: the outer step ``dt`` (s) of the method; the first ``head``
    contacts (0: none, single rate) are integrated inside each drift by substeps of the
    same method of at most ``inner_dt`` (s)."""

    dt: float
    head: int = 0
    inner_dt: float = math.inf

    def substeps(self, step: float, drifts) -> np.ndarray:
        """Substeps in each drift a_s * step (int64; 0 when there is no head)."""
        if self.head == 0:
            return np.zeros(len(drifts), np.int64)
        return np.array([max(1, math.ceil(abs(a) * step / self.inner_dt * (1 - 1e-12))) for a in drifts], np.int64)


def _reduced_masses(p) -> np.ndarray:
    """Reduced mass (kg) of each contact slot's two bodies (the wall is infinitely heavy)."""
    out = np.full(p.n_bodies, np.nan)
    out[1:] = 1.0 / (p.invm[:-1] + p.invm[1:])
    return out


def contact_time_scales(p) -> np.ndarray:
    """tau (s) of each contact slot (formula in the module doc; inf where no contact);
    computed once per problem."""
    return computed_once(p, "contact_time_scales", lambda: _contact_time_scales(p))


def _contact_time_scales(p) -> np.ndarray:
    m = _reduced_masses(p)
    live = p.A > 0
    tau = np.full(p.n_bodies, np.inf)
    v = float(p.v0.max(initial=0.0))
    if v > 0:
        tau[live] = (m[live] / (p.A[live] * math.sqrt(v))) ** 0.4
    loaded = live & (p.f0 > 0)
    tau[loaded] = np.minimum(tau[loaded], np.sqrt(m[loaded] / contact_stiffness(p.A[loaded], p.f0[loaded])))
    return tau


def contact_time_scale(p, first: int = 1) -> float:
    """tau (s): the shortest contact time scale of slots ``first``.. (formula in the module doc)."""
    return float(np.min(contact_time_scales(p)[first:], initial=math.inf))


def fast_head(p) -> int:
    """How many leading contacts are stiff enough to be integrated apart (0: none)."""
    tau = contact_time_scales(p)[1:]
    finite = tau[np.isfinite(tau)]
    if p.chain.law.dissipative or finite.size < 2 * MAX_HEAD:
        return 0
    slow = HEAD_RATIO * float(np.median(finite))
    k = 0
    while k < MAX_HEAD and tau[k] < slow:
        k += 1
    return k


def peak_force_estimate(p) -> np.ndarray:
    """Upper estimate of each contact's peak force (N): static force plus twice the peak of
    the striker hitting an immovable sphere, F = A (5 m_s v^2 / (4 A))^(3/5)."""
    F = p.f0.copy()
    if p.offset and p.v0[0] > 0:
        A0 = p.A[1]
        hit = A0 * (5.0 * p.mass[0] * p.v0[0] ** 2 / (4.0 * A0)) ** 0.6
        F = F + 2.0 * hit
    return F


def max_frequency(p, first: int = 1) -> float:
    """Gershgorin bound (rad/s) on the highest linear frequency at the peak-force estimate,
    counting the contacts of slots ``first``.. only."""
    k = np.where(p.A > 0, contact_stiffness(p.A, peak_force_estimate(p)), 0.0)
    k[:first] = 0.0
    k_above = k
    k_below, im_above, im_below = np.zeros_like(k), np.zeros_like(k), np.zeros_like(k)
    im = p.invm
    k_below[:-1], im_above[1:], im_below[:-1] = k[1:], im[:-1], im[1:]
    rows = im * (k_above + k_below) + k_above * np.sqrt(im * im_above) + k_below * np.sqrt(im * im_below)
    return float(math.sqrt(rows.max())) if rows.max() > 0 else 0.0


def stability_limit(p, method: Method, head: int = 0) -> float:
    """Largest stable step (s) for this chain and method (inf if nothing is loaded); with a
    multirate head, the outer step's limit (the head's contacts are substepped)."""
    w = max_frequency(p, head + 1)
    return method.stability / w if w > 0 else math.inf


def accuracy_step(p, method: Method, accuracy: float, head: int = 0) -> float:
    """Step (s) meeting ``accuracy`` over a pulse crossing every moving body, from the
    contacts after the head."""
    tau = contact_time_scale(p, head + 1)
    return tau * (accuracy / (method.error_constant * max(p.moving_bodies, 1))) ** (1.0 / method.contact_order)


def single_rate_step(p, method: Method, accuracy: float) -> float:
    """The single-rate step (s): the accuracy step, at most half the stability limit."""
    return min(accuracy_step(p, method, accuracy), 0.5 * stability_limit(p, method))


def checked_accuracy(accuracy: float | None) -> float:
    """The accuracy target of a solve: DEFAULT_ACCURACY when None; refused outside
    [1e-14, 0.1] (relative force error)."""
    accuracy = DEFAULT_ACCURACY if accuracy is None else accuracy
    if not (isinstance(accuracy, (int, float)) and 1e-14 <= accuracy <= 0.1):
        raise invalid("accuracy", accuracy, "relative accuracy target in [1e-14, 0.1]")
    return accuracy


def default_step(p, method: Method, accuracy: float) -> Stepping:
    """The stepping a solve takes by itself. Single rate: ``single_rate_step``. With a
    stiff head (``fast_head``): HEAD_SUBSTEP x that step for the head's substeps, and an
    outer step from the slow contacts, at most half their stability limit and at most the
    head's tau."""
    single = single_rate_step(p, method, accuracy)
    head = fast_head(p)
    if head == 0:
        return Stepping(single)
    outer = min(accuracy_step(p, method, accuracy, head), 0.5 * stability_limit(p, method, head),
                contact_time_scale(p))
    return Stepping(outer, head, HEAD_SUBSTEP * single) if outer > single else Stepping(single)
