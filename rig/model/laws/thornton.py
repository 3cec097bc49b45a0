"""Thornton's elastic-plastic contact with memory, its yield rising with the loading rate.

Loading a virgin contact (Thornton, J. Appl. Mech. 64, 383 (1997), there for Hertz's n = 3/2):

    F = A delta^n                                   delta <= delta_y
    F = F_y + k_y (delta - delta_y)                 delta >  delta_y   (the plastic envelope)

with delta_y = (F_y / A)^(1/n) the overlap at yield and k_y = n F_y / delta_y the elastic law's
tangent there (for Hertz, k_y = pi p_y R*: the contact pressure held at the yield pressure
p_y). Each contact remembers its largest load (delta*, F*): unloading and reloading below it
are elastic with the enlarged radius and the permanent overlap,

    F = A_p (delta - delta_p)^n,   delta_p = delta* - n F* / k_u,   A_p = F* / (n F* / k_u)^n,
    k_u = k_y sqrt((2 F* + F_y) / (3 F_y))

(k_u: Thornton's unloading stiffness 2 E* a_p, the contact radius a_p^2 = a_y^2 (2F* + F_y) /
(3 F_y); for n = 3/2 this is Thornton's R_p and delta_p exactly). The contact yields again
where its elastic curve meets the envelope (its elastic limit).

Each contact yields at its own force. A material yields at a pressure: Hertz's peak
pressure reaches p_y (chain.yield_pressure) at F_y = pi^3 R*^2 p_y^3 / (6 E*^2)
(pressure_yield_force), so a steel-PTFE contact (E* about twice PTFE-PTFE's) yields at about a
quarter of the PTFE-PTFE force and a bead on a flat wall near it (R* twice, E* about
twice). chain.yield_force, the older key, gives the yield force of the chain's own bead-bead
contacts, read as the pressure that yields them there (yield_pressure_of); the other
contacts yield at that pressure too. With an exponent other than Hertz's (a power law
matched to Hertz) chain.yield_force is every contact's force, as before.

The yield rises with the loading rate (polymers: Rae & Dattelbaum, Polymer 45, 7615 (2004);
a rate-dependent yield in granular chains: Burgoyne & Daraio, Phys. Rev. E 89, 032203
(2014)): above the reference closing rate r_ref the yield pressure goes as (r / r_ref)^m, r
the largest closing rate (m/s) the contact has seen, so that (p ~ delta^(1/2) at Hertz's
yield, F_y = A delta_y^n)

    F_y(r) = F_y (r / r_ref)^(2 n m),   delta_y(r) = delta_y (r / r_ref)^(2 m)    (r > r_ref);

m = 0: a rate-independent yield. A **static hold** (magnet.hold seconds of the magnet's load
before the shot; the model does not follow creep during it, any hold > 0 counts the same)
flattens each contact at its static force with the static yield pressure, static_yield_ratio x
the dynamic one: contacts pre-flattened so are stiffer, and yield later under the pulse, which
is how precompression changes the dissipation. Without a hold a static force beyond the
dynamic yield flattens its contact too (the load was put on once).

Memory in a step. A contact's memory changes only at step ends (``commit``): inside a step its
force is a fixed function of the overlap (the elastic curve up to its elastic limit, the
envelope beyond), so that every stage of the composition sees one conservative force (the
stages of a composition move off the trajectory and back: a memory renewed at each would
keep their overshoot); the step's largest overlap (at its end, or the peak of the overlap's
cubic Hermite interpolant where the contact turned back in the step) and the closing rate are
taken at the step's end.

Energy: inside a step the contact has the potential plastic_energy; at a commit the potential
it loses (the envelope's work less the energy left on the new elastic curve) becomes plastic
work, so that kinetic + elastic + plastic work stays the striker's energy to the integrator's
error.

The functions marked ``kernel`` below are the kernels' (rig/solver/kernels compiles them, so
that importing this module loads no numba): a contact's state is its column of ``state``
(STATE_ROWS), the same in the single-shot and batched kernels.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from numerics.jit import kernel
from rig.model.laws import dashpot
from rig.model.laws.law import PLASTIC, ContactLaw, LawParameter, ViscousTerms

YIELD_FORCE = LawParameter("yield_force", "N", 0.0, float("inf"), 0.0,
                           "force F_y (N) at which a virgin contact yields, closing at the reference rate",
                           switch=True)
RATE_EXPONENT = LawParameter("yield_rate_exponent", "1", 0.0, 0.5, 0.0,
                             "exponent m of the yield pressure's rise with the closing rate above the "
                             "reference rate, p_y ~ (r / r_ref)^m (0: a rate-independent yield)")
REFERENCE_RATE = LawParameter("yield_reference_rate", "m/s", 0.0, float("inf"), 0.01,
                              "closing rate r_ref (m/s) at and below which a contact yields at "
                              "chain.yield_force (a pulse's contacts close at 0.01-1 m/s)", lo_open=True)
YIELD_PRESSURE = LawParameter("yield_pressure", "Pa", 0.0, float("inf"), 0.0,
                              "pressure p_y (Pa) at which a virgin contact yields, closing at the reference rate: "
                              "each contact at its own force F_y = pi^3 R*^2 p_y^3 / (6 E*^2) (0: from "
                              "chain.yield_force)")
STATIC_RATIO = LawParameter("static_yield_ratio", "1", 0.05, 1.0, 1.0,
                            "yield pressure of a static hold over the dynamic one (chain.yield_force's)")

STATE_ROWS = ("permanent_overlap", "unloading_constant", "largest_rate", "yield_overlap", "plastic_work",
              "reference_yield_overlap", "elastic_limit", "last_overlap", "last_rate", "shifted_rest_overlap")
"""A contact's memory, the rows of the kernels' ``state`` (10, slots): its elastic curve's
delta_p (m) and A_p (N/m^n), the largest closing rate seen (m/s), delta_y at that rate (m),
the plastic work it has taken in the shot (J), delta_y at r_ref (m; 0: it never yields), the
overlap up to which the elastic curve holds (m; inf: it never yields), the overlap (m) and
its rate (m/s) at the last step's end, and the rest overlap less delta_p (m): the kernels'
Hertz passes take A_p and d0 - delta_p for A and d0, and so give the elastic curve."""
DP, AP, RMAX, DY, WORK, DYREF, DC, DLAST, RLAST, DS = range(10)
SPAN_FIRST, SPAN_END = DLAST, RLAST
"""Slot 0 joins no bodies: its DLAST and RLAST hold, for each shot, the slots the kernels'
force passes check for the envelope, SPAN_FIRST <= i < SPAN_END (rig/solver/kernels/memory.py)."""
BISECTIONS = 60  # halvings of the bracket of an elastic limit (2^-60: below a float's spacing)

@dataclass(frozen=True)
class YieldTerms:
    """What the law hands the kernels for each of its contacts: yield force F_y (N) at the
    reference closing rate r_ref (m/s), the rate exponent m, and static_yield_ratio, the
    static yield pressure of a hold over the dynamic one. F_y = 0: the contact never yields."""

    yield_force: float = 0.0
    rate_exponent: float = 0.0
    reference_rate: float = 1.0
    static_ratio: float = 1.0
    yield_pressure: float = 0.0


NO_YIELD = YieldTerms()


def yield_terms(values: dict) -> YieldTerms:
    """The chain's values ({key: SI value}) as YieldTerms."""
    return YieldTerms(values["yield_force"], values["yield_rate_exponent"], values["yield_reference_rate"],
                      values["static_yield_ratio"], values["yield_pressure"])


def pressure_yield_force(p_y, R, A):
    """F_y (N) at which a Hertz contact of reduced radius R* (m) and constant A (N/m^1.5)
    reaches the yield pressure p_y (Pa) at its centre: Hertz's peak pressure p0 = (6 F E*^2 /
    (pi^3 R*^2))^(1/3) reaches p_y at F_y = pi^3 R*^2 p_y^3 / (6 E*^2), and with E* = 3 A /
    (4 sqrt(R*)), F_y = 8 pi^3 p_y^3 R*^3 / (27 A^2). 0 where there is no contact."""
    p, R, A = np.broadcast_arrays(np.asarray(p_y, float), np.asarray(R, float), np.asarray(A, float))
    ok = np.isfinite(R) & np.isfinite(A) & (A > 0)
    out = np.zeros(A.shape)
    out[ok] = 8.0 * math.pi**3 * p[ok] ** 3 * R[ok] ** 3 / (27.0 * A[ok] ** 2)
    return out


def yield_pressure_of(F_y, R, A):
    """The yield pressure p_y (Pa) at which a Hertz contact (R* m, A N/m^1.5) yields at F_y
    (N): pressure_yield_force's inverse, p_y = (27 F_y A^2 / (8 pi^3 R*^3))^(1/3)."""
    return (27.0 * F_y * A**2 / (8.0 * math.pi**3 * R**3)) ** (1.0 / 3.0)


def viscous_terms(values: dict) -> ViscousTerms:
    """A linear dashpot of mu kg/s beside the plastic contact (0: none)."""
    return ViscousTerms(dashpot=values["contact_damping"])


@kernel
def elastic_power(d, n):
    """d^n for d >= 0 (d sqrt(d) for Hertz's 3/2, exactly as the kernels' Hertz passes)."""
    if n == 1.5:
        return d * math.sqrt(d)
    return d**n


@kernel
def unloading(d, F, Fy, dy, n):
    """(delta_p, A_p): the elastic curve through (d, F) (m, N) of a contact yielding at Fy
    (N) at overlap dy (m): Thornton's k_u = k_y sqrt((2F + Fy) / (3 Fy)), k_y = n Fy / dy."""
    ku = n * Fy / dy * math.sqrt((2.0 * F + Fy) / (3.0 * Fy))
    de = n * F / ku
    return d - de, F / elastic_power(de, n)


@kernel
def envelope(d, A, n, dy):
    """Force (N) on the loading envelope at overlap d (m): A d^n up to dy, then the tangent line."""
    if d <= dy:
        return A * elastic_power(d, n)
    Fy = A * elastic_power(dy, n)
    return Fy + n * Fy / dy * (d - dy)


@kernel
def envelope_work(a, b, A, n, dy):
    """The envelope's work (J) from overlap a to b >= a (m): A x^(n+1) / (n+1) below dy, a
    trapezoid on the line beyond."""
    w = 0.0
    if a < dy:
        hi = min(b, dy)
        w += A * (hi * elastic_power(hi, n) - a * elastic_power(a, n)) / (n + 1.0)
    if b > dy:
        lo = max(a, dy)
        w += 0.5 * (envelope(lo, A, n, dy) + envelope(b, A, n, dy)) * (b - lo)
    return w


@kernel
def plastic_force(d, A, n, state, i, s):
    """Force (N) of contact i of shot s at overlap d (m) by its memory state[:, i, s], which a
    step holds fixed: its elastic curve A_p (d - d_p)^n up to its elastic limit, the
    envelope beyond (0 where d <= d_p)."""
    if d <= state[DC, i, s]:
        de = d - state[DP, i, s]
        if not de > 0.0:
            return 0.0
        if n == 1.5:  # (A_p d) sqrt(d): the Hertz passes' operations, their bits as new
            return state[AP, i, s] * de * math.sqrt(de)
        return state[AP, i, s] * elastic_power(de, n)
    return envelope(d, A, n, state[DY, i, s])


@kernel
def plastic_energy(d, A, n, state, i, s):
    """The potential (J) of plastic_force at overlap d (m) for the memory state[:, i, s]:
    A_p (x - d_p)^(n+1) / (n+1) at x = min(d, elastic limit), plus the envelope's work
    beyond, plus the plastic work the contact has taken."""
    dc = state[DC, i, s]
    de = min(d, dc) - state[DP, i, s]
    u = state[AP, i, s] * de * elastic_power(de, n) / (n + 1.0) if de > 0.0 else 0.0
    if d > dc:
        u += envelope_work(dc, d, A, n, state[DY, i, s])
    return u + state[WORK, i, s]


@kernel
def elastic_limit(A, n, dp, ap, dy, start):
    """The overlap (m) from ``start`` on where the elastic curve A_p (x - d_p)^n meets the
    envelope of yield overlap dy (A, n the contact's elastic law; bisection: the curve
    is below the envelope at start and, steeper, above it far enough on)."""
    lo = max(start, dp)
    step = max(lo - dp, dy)
    hi = lo + step
    for _ in range(BISECTIONS):
        if ap * elastic_power(hi - dp, n) > envelope(hi, A, n, dy):
            break
        step *= 2.0
        hi = lo + step
    for _ in range(BISECTIONS):
        mid = 0.5 * (lo + hi)
        if ap * elastic_power(mid - dp, n) > envelope(mid, A, n, dy):
            hi = mid
        else:
            lo = mid
    return lo


@kernel
def hermite_peak(y0, m0, y1, m1):
    """The largest value of the cubic Hermite polynomial through y0, y1 with slopes m0 > 0 >
    m1 (per unit of the interval) on [0, 1]: at the one root there of its derivative
    a x^2 + b x + m0 (the stable form of the quadratic's roots), written in y1 - y0 so that the
    small change of a large overlap keeps its digits."""
    dy = y1 - y0
    a = -6.0 * dy + 3.0 * m0 + 3.0 * m1
    b = 6.0 * dy - 4.0 * m0 - 2.0 * m1
    q = -0.5 * (b + math.copysign(math.sqrt(max(b * b - 4.0 * a * m0, 0.0)), b))
    x = q / a if a != 0.0 else -1.0
    if not 0.0 <= x <= 1.0:
        x = m0 / q if q != 0.0 else 0.5
    x = min(max(x, 0.0), 1.0)
    x2 = x * x
    return y0 + (3.0 * x2 - 2.0 * x2 * x) * dy + (x2 * x - 2.0 * x2 + x) * m0 + (x2 * x - x2) * m1


@kernel
def commit(d, rate, dt, A, d0, n, m, r_ref, state, i, s):
    """Renew the memory of contact i of shot s at a step's end: overlap d (m), closing rate
    ``rate`` (m/s), dt (s) after the last (d0: its rest overlap, m). The step's largest overlap: d, or where the
    contact turned back in the step (closing at its start, opening at its end) the peak of
    the cubic Hermite through both ends. Where that passed the elastic limit the contact
    yielded there: its new elastic curve runs through (peak, envelope(peak)), and the
    potential it lost at d counts as plastic work. Where the closing rate passes the
    largest seen and r_ref (m > 0), the yield overlap rises as (rate / r_ref)^(2 m) and the
    elastic limit with it."""
    d_last, r_last = state[DLAST, i, s], state[RLAST, i, s]
    state[DLAST, i, s] = d
    state[RLAST, i, s] = rate
    peak = d
    if r_last > 0.0 and rate < 0.0:
        peak = hermite_peak(d_last, r_last * dt, d, rate * dt)
    dy = state[DY, i, s]
    if peak > state[DC, i, s] and peak > state[DP, i, s]:
        before = plastic_energy(d, A, n, state, i, s)
        F = envelope(peak, A, n, dy)
        dp, ap = unloading(peak, F, A * elastic_power(dy, n), dy, n)
        state[DP, i, s] = dp
        state[AP, i, s] = ap
        state[DS, i, s] = d0 - dp
        state[DC, i, s] = peak
        state[WORK, i, s] = before - (plastic_energy(d, A, n, state, i, s) - state[WORK, i, s])
    if m != 0.0 and rate > state[RMAX, i, s]:
        state[RMAX, i, s] = rate
        if rate > r_ref:
            dy_new = state[DYREF, i, s] * (rate / r_ref) ** (2.0 * m)
            if dy_new > dy:
                state[DY, i, s] = dy_new
                state[DC, i, s] = elastic_limit(A, n, state[DP, i, s], state[AP, i, s], dy_new, max(peak, d))


def yield_overlap(A, Fy, n):
    """delta_y = (F_y / A)^(1/n) (m) of contacts of constants A (N/m^n) yielding at F_y (N); 0
    where F_y = 0 (no yield) or there is no contact (A = 0)."""
    A, Fy, n = np.broadcast_arrays(np.asarray(A, float), np.asarray(Fy, float), np.asarray(n, float))
    ok = (Fy > 0) & (A > 0)
    out = np.zeros(A.shape)
    out[ok] = (Fy[ok] / A[ok]) ** (1.0 / n[ok])
    return out


def initial_state(A, n, F_static, d_static, terms: YieldTerms, yield_forces, hold: float = 0.0) -> tuple:
    """(state, d0, hold_work): the kernels' memory (STATE_ROWS, contacts) before the shot,
    the static overlaps d0 (m) and the plastic work (J, per contact) the static load took
    (before the shot: not in its energy), for contacts of constants A (N/m^n), exponents n,
    static forces F_static (N) and elastic static overlaps d_static (m).

    A contact whose static force passes its yield force was flattened as the load went on:
    it rests on its elastic curve through (delta*, F_static) on the envelope, at delta* >
    d_static. The yield is each contact's own, ``yield_forces`` (N; a yield pressure's,
    Chain.contact_yield_forces); after a static hold (``hold`` > 0 s) the static one,
    static_ratio x its pressure (the yield overlap x ratio^2, the force x ratio^(2n)). The
    others are as new (A_p = A, delta_p = 0) at d_static. Each yields again where its curve
    meets its dynamic envelope (elastic_limit)."""
    A, n, F, d0 = (np.array(x, float) for x in np.broadcast_arrays(A, n, F_static, d_static))
    state = np.zeros((len(STATE_ROWS),) + A.shape)
    dy = yield_overlap(A, yield_forces, n)
    state[AP], state[DY], state[DYREF] = A, dy, dy
    state[DC] = np.where(dy > 0, dy, np.inf)
    work = np.zeros(A.shape)
    dys = dy * (terms.static_ratio**2 if hold > 0 else 1.0)
    flat = dys > 0
    flat[flat] = A[flat] * dys[flat] ** n[flat] < F[flat]  # past the yield (the power only where one is)
    for k in zip(*np.nonzero(flat)):  # the contacts loaded past their yield, by the kernels' own functions
        a, m, f, y = A[k], n[k], F[k], dys[k]
        fy = a * elastic_power(y, m)
        d_star = y + (f - fy) / (m * fy / y)  # on the envelope's line
        dp, ap = unloading(d_star, f, fy, y, m)
        state[DP][k], state[AP][k] = dp, ap
        state[DC][k] = elastic_limit(a, m, dp, ap, dy[k], d_star)
        work[k] = envelope_work(0.0, d_star, a, m, y) - f * (d_star - dp) / (m + 1.0)
        d0[k] = d_star
    state[DLAST] = d0
    return state, d0, work


def rest_after(memory, n, F_static, d_static) -> tuple:
    """(state, d0): a contact's memory kept from a shot (STATE_ROWS, contacts; the kernels'
    state at the shot's end) at rest again under its static force F_static (N): on its
    elastic curve F = A_p (d - d_p)^n, d0 = d_p + (F / A_p)^(1/n) where the shot flattened
    it (d_p > 0), else its elastic static overlap d_static (m); the plastic work and the
    last closing rate zeroed, the last overlap d0. Its largest rate, yield overlaps and
    elastic limit are kept: the next shot meets the flattened contacts."""
    state = np.array(memory, dtype=float, copy=True)
    n, F, d0 = (np.array(x, float) for x in np.broadcast_arrays(n, F_static, d_static))
    dp, ap = state[DP], state[AP]
    flat = (dp > 0) & (ap > 0) & (F > 0)
    d0[flat] = dp[flat] + (F[flat] / ap[flat]) ** (1.0 / n[flat])
    state[WORK], state[RLAST], state[DLAST] = 0.0, 0.0, d0
    return state, d0


LAW = ContactLaw(
    "thornton",
    "elastic-plastic with memory (Thornton, J. Appl. Mech. 64, 383 (1997)): elastic A delta^n up to the yield "
    "force, each contact's own at the yield pressure chain.yield_pressure (or the one chain.yield_force gives "
    "the chain's bead-bead contacts), then the tangent line; unloading and reloading elastic with the enlarged radius "
    "and the permanent overlap; the yield pressure rises as (rate / chain.yield_reference_rate)^"
    "chain.yield_rate_exponent; magnet.hold seconds of the magnet's load flatten the contacts before the "
    "shot at static_yield_ratio x that yield; an optional linear dashpot chain.contact_damping beside it",
    (YIELD_FORCE, YIELD_PRESSURE, RATE_EXPONENT, REFERENCE_RATE, STATIC_RATIO, dashpot.CONTACT_DAMPING),
    viscous_terms, PLASTIC, yield_terms)
