"""Choosing the time step: contact time scale, the a-priori rule, stability, the head.

Contact time scale (Nesterenko 2001; the duration of a Hertz collision scales with it):

    tau = min over contacts of  (m / (A v^(1/2)))^(2/5)     impact at speed v
                        and     sqrt(m / k0),  k0 = (3/2) A^(2/3) F0^(1/3)   precompressed

with m the reduced mass of the two bodies. A pulse that crosses N contacts accumulates a
phase error ~ N (dt/tau)^p, so for a target relative force error ``accuracy``

    dt = tau * (accuracy / (C N))^(1/p)

with the method's contact order p and error constant C, N the contacts a pulse crosses in
the whole record (``crossed_contacts``: the distance it travels, reflections included, not
the length of the chain). This rule only starts the accuracy control
(rig/solver/control.py), which measures the error and moves the step: C is set from the
easiest of the measured problems, so that a first try is cheap (docs/solver.md). The step
is also kept below half the linear stability limit omega_max dt < S (S from the method's
coefficients), with omega_max bounded by Gershgorin's theorem on the chain linearised at an
upper estimate of the peak forces.

The head. The contacts that close and open at speed (the striker's; behind it, in a chain
without precompression, the first beads', which fly apart after the pulse) are split off
(r-RESPA / impulse multiple time stepping, Tuckerman, Berne & Martyna 1992): each drift of
the method becomes the flow of kinetic energy + the head's contacts, integrated by
substeps of the same method (rig/solver/kernels/multirate.py), which resolve the instants
a contact closes or opens; the method's kicks carry the other contacts. A stiff striker
(alumina on the steel magnetic bead: tau 3.7 us against 16 us in the PTFE) then no longer
sets the step of the whole chain: the head's substep is HEAD_SUBSTEP x the outer step x
the ratio of the taus, and the outer step follows the slow contacts, at most MTS_CAP head
taus (away from the resonances of multiple time stepping).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rig.errors import invalid
from rig.memo import computed_once
from rig.model.contact import contact_stiffness
from rig.solver.methods import Method
from rig.theory.longwave import sonic_vacuum_speed, sound_speed
from rig.units import is_real, is_whole

DEFAULT_ACCURACY = 1e-4
HEAD_RATIO = 0.5   # a leading contact with tau < HEAD_RATIO x median tau is integrated apart
MAX_HEAD = 3       # at most this many leading contacts form the head
HEAD_SUBSTEP = 0.5  # the head's substep: this fraction of the outer step, in units of tau
MTS_CAP = 2.0      # the outer step stays below this many head taus


@dataclass(frozen=True)
class Stepping:
    """How a solve steps: the outer step ``dt`` (s) of the method; the first ``head``
    contacts (0: none, single rate) are integrated inside each drift by substeps of the
    same method of at most ``inner_dt`` (s)."""

    dt: float
    head: int = 0
    inner_dt: float = math.inf

    def __post_init__(self):
        if not is_whole(self.head) or self.head < 0:
            raise invalid("dt.head", self.head, "the head's contacts: a whole number >= 0")
        if not is_real(self.inner_dt) or not self.inner_dt > 0:
            raise invalid("dt.inner_dt", self.inner_dt, "the head's substep: a number > 0 s (inf: none)")

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
    """For a power law A d^n the impact scale is (m / (A v^(n-1)))^(1/(n+1)), the same
    dimensional argument as Hertz's."""
    m = _reduced_masses(p)
    live = p.A > 0
    tau = np.full(p.n_bodies, np.inf)
    v = float(p.v0.max(initial=0.0))
    hertz = live & (p.expo == 1.5)
    other = live & ~hertz
    if v > 0:
        tau[hertz] = (m[hertz] / (p.A[hertz] * math.sqrt(v))) ** 0.4
        n = p.expo[other]
        tau[other] = (m[other] / (p.A[other] * v ** (n - 1.0))) ** (1.0 / (n + 1.0))
    loaded = live & (p.f0 > 0)
    k0 = contact_stiffness(p.A[loaded], p.f0[loaded], p.expo[loaded])
    tau[loaded] = np.minimum(tau[loaded], np.sqrt(m[loaded] / k0))
    return tau


def contact_time_scale(p, first: int = 1) -> float:
    """tau (s): the shortest contact time scale of slots ``first``.. (formula in the module doc)."""
    return float(np.min(contact_time_scales(p)[first:], initial=math.inf))


def head_contacts(p) -> int:
    """How many leading contacts are integrated apart, by the head flow (0: none): the
    striker's contact, and after it, up to MAX_HEAD in all, each leading contact that is
    much stiffer than the chain's (tau below HEAD_RATIO x the median tau) or that carries
    no static load (it opens behind the pulse with the beads flying apart). These are the
    contacts that close and open at speed, and the head flow resolves those instants."""
    tau = contact_time_scales(p)[1:]
    finite = tau[np.isfinite(tau)]
    elastic = (p.expo == 1.5) & (p.damping == 0.0) & (p.dashpot == 0.0) & (p.reference_yield_overlap == 0.0)  # Hertz
    if not p.offset or finite.size < 2 * MAX_HEAD or not elastic[1]:
        return 0
    slow = HEAD_RATIO * float(np.median(finite))
    k = 1
    while k < MAX_HEAD and elastic[k + 1] and (tau[k] < slow or p.f0[k + 1] == 0.0):
        k += 1
    return k


def peak_force_estimate(p) -> np.ndarray:
    """Upper estimate of each contact's peak force (N): static force plus twice the peak of
    the striker hitting an immovable sphere, F = A (5 m_s v^2 / (4 A))^(3/5) (a power law
    A d^n: A ((n + 1) m_s v^2 / (2 A))^(n/(n+1))). Arrays (bodies,), or (shots, bodies)
    for a batch's ProblemArrays."""
    F = np.array(p.f0, dtype=float)
    if not p.offset:
        return F
    m, v, A0, n = p.mass[..., 0], p.v0[..., 0], p.A[..., 1], p.expo[..., 1]
    with np.errstate(invalid="ignore", divide="ignore"):
        hertz = A0 * (5.0 * m * v**2 / (4.0 * A0)) ** 0.6
        other = A0 * ((n + 1.0) * m * v**2 / (2.0 * A0)) ** (n / (n + 1.0))
    hit = np.where(v > 0, np.where(n == 1.5, hertz, other), 0.0)
    return F + 2.0 * np.asarray(hit)[..., None]


def max_frequency(p, first: int = 1) -> float:
    """Gershgorin bound (rad/s) on the highest linear frequency at the peak-force estimate,
    counting the contacts of slots ``first``.. only."""
    k = np.where(p.A > 0, contact_stiffness(p.A, peak_force_estimate(p), p.expo), 0.0)
    k[:first] = 0.0
    k_above = k
    k_below, im_above, im_below = np.zeros_like(k), np.zeros_like(k), np.zeros_like(k)
    im = p.invm
    k_below[:-1], im_above[1:], im_below[:-1] = k[1:], im[:-1], im[1:]
    rows = im * (k_above + k_below) + k_above * np.sqrt(im * im_above) + k_below * np.sqrt(im * im_below)
    return float(math.sqrt(rows.max())) if rows.max() > 0 else 0.0


def viscous_rate(p) -> float:
    """A bound (1/s) on the decay rates of the contacts' viscous flow (the dissipation's
    substeps, rig/solver/kernels/dissipation.py): Gershgorin's on M^-1 L, L the chain's
    Laplacian weighted by each contact's viscous coefficient c = mu + A tau d^(n-1) at
    the peak-force estimate (a power-law dashpot's mu |d'|^(alpha-1) at the largest initial
    speed, the striker's, or 1 m/s without one: the dissipation's substeps hold it stable
    at any rate); 0 without viscous terms. A ChainProblem, or a batch's ProblemArrays (the
    largest over its shots)."""
    if not (np.any(p.damping) or np.any(p.dashpot)):
        return 0.0
    live = p.A > 0
    F = peak_force_estimate(p)
    speed = float(np.max(np.abs(p.v0))) or 1.0
    with np.errstate(invalid="ignore", divide="ignore"):
        d = np.where(live, (F / np.where(live, p.A, 1.0)) ** (1.0 / p.expo), 0.0)
        dashpot = np.where(p.dashpot_exponent == 1.0, p.dashpot, p.dashpot * speed ** (p.dashpot_exponent - 1.0))
        c = np.where(live, dashpot + p.damping * p.A * d ** (p.expo - 1.0), 0.0)
    c_below = np.zeros_like(c)
    c_below[..., :-1] = c[..., 1:]
    return float(np.max(2.0 * (c + c_below) * p.invm))


def stability_limit(p, method: Method, head: int = 0) -> float:
    """Largest stable step (s) for this chain and method (inf if nothing is loaded); with a
    multirate head, the outer step's limit (the head's contacts are substepped)."""
    w = max_frequency(p, head + 1)
    return method.stability / w if w > 0 else math.inf


def crossed_contacts(p, t_end: float) -> float:
    """How many contacts a pulse crosses in t_end seconds (at least 1): t_end x the pulse
    speed / the bead spacing, reflections and returns included. The speed is the larger of
    the long-wave sound speed at the largest static force (Eq 2) and the sonic-vacuum speed
    of the peak-force estimate (Eq 4), for beads of the chain's median mass, spacing and
    contact constant (E/(1 - nu^2) = 3 A / sqrt(a), rho = 6 m / (pi a^3))."""
    live = (p.A > 0) & (np.arange(p.n_bodies) > p.offset)
    if p.wall_slot:
        live[p.wall_slot] = False
    beads = p.chain.beads
    a = 2.0 * float(np.median([b.radius for b in beads]))
    if not live.any():
        return 1.0
    A = float(np.median(p.A[live]))
    m = float(np.median(p.chain.masses))
    if np.any(p.expo[live] != 1.5):  # another exponent: the linear sound speed at the peak force bounds it
        n = float(np.median(p.expo[live]))
        k = float(contact_stiffness(A, float(peak_force_estimate(p)[live].max()), n))
        return max(1.0, a * math.sqrt(k / m) * t_end / a)
    modulus, rho = 3.0 * A / math.sqrt(a), 6.0 * m / (math.pi * a**3)
    speed = max(float(sound_speed(modulus, 0.0, rho, a, float(p.f0[live].max()))),
                float(sonic_vacuum_speed(modulus, 0.0, rho, a, float(peak_force_estimate(p)[live].max()))))
    return max(1.0, speed * t_end / a)


def accuracy_step(p, method: Method, accuracy: float, t_end: float, head: int = 0) -> float:
    """Step (s) meeting ``accuracy`` over t_end seconds, from the contacts after the head:
    dt = tau (accuracy / (C N))^(1/p), N the contacts a pulse crosses (crossed_contacts)."""
    tau = contact_time_scale(p, head + 1)
    n = crossed_contacts(p, t_end)
    return tau * (accuracy / (method.error_constant * n)) ** (1.0 / method.contact_order)


def stepping_at(p, dt: float, head: int | None = None) -> Stepping:
    """The stepping of outer step dt (s): the head of ``head_contacts`` (or ``head``), its
    substep HEAD_SUBSTEP x dt x (the head's tau / the chain's): the head's contacts taken
    at half the chain's relative step."""
    head = head_contacts(p) if head is None else head
    if head == 0:
        return Stepping(dt)
    ratio = contact_time_scale(p) / contact_time_scale(p, head + 1)
    return Stepping(dt, head, HEAD_SUBSTEP * dt * min(ratio, 1.0))


FINEST_ACCURACY = 1e-10  # below it the estimate cannot tell the error from rounding: a channel the pulse
# has not reached is measured against 1e-6 of the largest peak (solution.relative_error), and its
# float64 wobble of an ulp is already 1e-10 of that; the control would shrink the step for minutes
COARSEST_ACCURACY = 0.1  # a force error of 10%: beyond it a record says nothing about the pulse


def checked_accuracy(accuracy: float | None, field: str = "accuracy") -> float:
    """The accuracy target of a solve: DEFAULT_ACCURACY when None; refused outside
    [FINEST_ACCURACY, COARSEST_ACCURACY] (relative force error), the message naming ``field``."""
    accuracy = DEFAULT_ACCURACY if accuracy is None else accuracy
    if not (is_real(accuracy) and FINEST_ACCURACY <= accuracy <= COARSEST_ACCURACY):
        raise invalid(field, accuracy, f"relative accuracy target in [{FINEST_ACCURACY:g}, {COARSEST_ACCURACY:g}]")
    return float(accuracy)


def largest_step(p, method: Method, t_end: float) -> float:
    """The largest outer step (s) a solve of t_end seconds may take: half the stability
    limit of the contacts after the head (a margin below it; the estimate's companion runs at
    half the step, stable wherever the solve is),
    with a head at most MTS_CAP x the head's tau (multiple time stepping resonates when
    the outer step nears the period of the fast contacts), and at most t_end."""
    head = head_contacts(p)
    dt = min(0.5 * stability_limit(p, method, head), t_end)
    return min(dt, MTS_CAP * contact_time_scale(p)) if head else dt


def default_step(p, method: Method, accuracy: float, t_end: float) -> Stepping:
    """The stepping a solve of t_end seconds starts from: the outer step of the a-priori
    rule (accuracy_step) from the contacts after the head, at most ``largest_step``; the
    head's substep from stepping_at."""
    head = head_contacts(p)
    return stepping_at(p, min(accuracy_step(p, method, accuracy, t_end, head), largest_step(p, method, t_end)), head)
