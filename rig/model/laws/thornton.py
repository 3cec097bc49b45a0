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
where, closing, its elastic curve passes the envelope.

The yield rises with the loading rate (polymers: Rae & Dattelbaum, Polymer 45, 7615 (2004);
a rate-dependent yield in granular chains: Burgoyne & Daraio, Phys. Rev. E 89, 032203
(2014)): the yield pressure goes as r^m, r the largest closing rate (m/s) the contact has
seen, so that (p ~ delta^(1/2) at Hertz's yield, F_y = A delta_y^n)

    F_y(r) = F_y (r / r_ref)^(2 n m),   delta_y(r) = delta_y (r / r_ref)^(2 m).

m = 0: a rate-independent yield. A **static hold** (chain.static_hold seconds of the magnet's
load before the shot) flattens each contact at its static force with the static yield
pressure, static_yield_ratio x the yield pressure at the hold's own loading rate r_hold =
delta_H / t_hold (delta_H the Hertz overlap of the static force): contacts pre-flattened so are
stiffer, and yield later, under the pulse, which is how precompression changes the
dissipation.

Energy: between yields the contact is elastic with U = A_p (delta - delta_p)^(n+1) / (n+1); a
yield at overlap delta moves U_old(delta) - U_new(delta) into plastic work, so that kinetic +
elastic + plastic work stays the striker's energy to the integrator's error.

The compiled functions below are the kernels' (rig/solver/kernels): a contact's state is its
column of ``state`` (STATE_ROWS), the same in the single-shot and batched kernels.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from instruments.jit import jit
from rig.model.laws import dashpot
from rig.model.laws.law import PLASTIC, ContactLaw, LawParameter, ViscousTerms

YIELD_FORCE = LawParameter("yield_force", "N", 0.0, float("inf"), 0.0,
                           "force F_y (N) at which a virgin contact yields, closing at the reference rate",
                           switch=True)
RATE_EXPONENT = LawParameter("yield_rate_exponent", "1", 0.0, 0.5, 0.0,
                             "exponent m of the yield pressure's rise with the closing rate, p_y ~ r^m "
                             "(0: a rate-independent yield)")
REFERENCE_RATE = LawParameter("yield_reference_rate", "m/s", 0.0, float("inf"), 1.0,
                              "closing rate r_ref (m/s) at which a contact yields at chain.yield_force",
                              lo_open=True)
STATIC_RATIO = LawParameter("static_yield_ratio", "1", 0.05, 1.0, 1.0,
                            "static yield pressure over the rate law's at the hold's loading rate "
                            "(1: the rate law alone)")
STATIC_HOLD = LawParameter("static_hold", "s", 0.0, float("inf"), 0.0,
                           "seconds the magnet's load is held before the shot, flattening the contacts "
                           "(0: contacts as new)")

STATE_ROWS = ("permanent_overlap", "unloading_constant", "largest_rate", "yield_overlap", "plastic_work",
              "reference_yield_overlap")
"""A contact's memory, the rows of the kernels' ``state`` (6, slots): delta_p (m), A_p (N/m^n),
the largest closing rate seen r (m/s), delta_y(r) (m), the plastic work it has taken in the
shot (J) and delta_y at r_ref (m; 0: the contact never yields)."""
DP, AP, RMAX, DY, WORK, DYREF = range(6)
RATE_FLOOR = 1e-9  # a rate (x r_ref) below which the rate law is held: a yield that stays > 0


@dataclass(frozen=True)
class YieldTerms:
    """What the law hands the kernels for each of its contacts: yield force F_y (N) at the
    reference closing rate r_ref (m/s), the rate exponent m, and the static hold: its
    duration (s) and static_yield_ratio. F_y = 0: the contact never yields."""

    yield_force: float = 0.0
    rate_exponent: float = 0.0
    reference_rate: float = 1.0
    static_ratio: float = 1.0
    hold: float = 0.0


NO_YIELD = YieldTerms()


def yield_terms(values: dict) -> YieldTerms:
    """The chain's values ({key: SI value}) as YieldTerms."""
    return YieldTerms(values["yield_force"], values["yield_rate_exponent"], values["yield_reference_rate"],
                      values["static_yield_ratio"], values["static_hold"])


def viscous_terms(values: dict) -> ViscousTerms:
    """A linear dashpot of mu kg/s beside the plastic contact (0: none)."""
    return ViscousTerms(dashpot=values["contact_damping"])


@jit(inline="always")
def elastic_power(d, n):
    """d^n for d >= 0 (d sqrt(d) for Hertz's 3/2, exactly as the kernels' Hertz passes)."""
    if n == 1.5:
        return d * math.sqrt(d)
    return d**n


@jit(inline="always")
def unloading(d, F, Fy, dy, n):
    """(delta_p, A_p): the elastic curve through (d, F) (m, N) of a contact yielding at Fy
    (N) at overlap dy (m): Thornton's k_u = k_y sqrt((2F + Fy) / (3 Fy)), k_y = n Fy / dy."""
    ku = n * Fy / dy * math.sqrt((2.0 * F + Fy) / (3.0 * Fy))
    de = n * F / ku
    return d - de, F / elastic_power(de, n)


@jit(inline="always")
def plastic_force(d, rate, A, n, m, r_ref, state, i, s):
    """Force (N) of contact i of shot s at overlap d (m) closing at ``rate`` (m/s), its
    memory in state[:, i, s] (STATE_ROWS) renewed: the largest rate, and where the contact
    yields (closing, its elastic curve above the envelope) its new elastic curve and the
    plastic work it took. Elastic A_p (d - d_p)^n otherwise, 0 where d <= d_p."""
    dp = state[DP, i, s]
    ap = state[AP, i, s]
    de = d - dp
    F = ap * elastic_power(de, n) if de > 0.0 else 0.0
    dy = state[DY, i, s]
    if dy > 0.0 and rate > 0.0 and de > 0.0:
        if rate > state[RMAX, i, s]:
            state[RMAX, i, s] = rate
            if m != 0.0:
                dy = state[DYREF, i, s] * max(rate / r_ref, RATE_FLOOR) ** (2.0 * m)
                state[DY, i, s] = dy
        if d > dy:
            Fy = A * elastic_power(dy, n)
            env = Fy + n * Fy / dy * (d - dy)
            if F > env:
                u_old = F * de / (n + 1.0)
                dp, ap = unloading(d, env, Fy, dy, n)
                state[DP, i, s] = dp
                state[AP, i, s] = ap
                state[WORK, i, s] += u_old - env * (d - dp) / (n + 1.0)
                F = env
    return F


@jit(inline="always")
def plastic_energy(d, n, state, i, s):
    """Elastic energy (J) A_p (d - d_p)^(n+1) / (n+1) of contact i of shot s at overlap d
    (m) on its present elastic curve, plus the plastic work it has taken."""
    de = d - state[DP, i, s]
    u = state[AP, i, s] * de * elastic_power(de, n) / (n + 1.0) if de > 0.0 else 0.0
    return u + state[WORK, i, s]


def yield_overlap(A, Fy, n):
    """delta_y = (F_y / A)^(1/n) (m) of contacts of constants A (N/m^n) yielding at F_y (N); 0
    where F_y = 0 (no yield) or there is no contact (A = 0)."""
    A, Fy, n = np.broadcast_arrays(np.asarray(A, float), np.asarray(Fy, float), np.asarray(n, float))
    ok = (Fy > 0) & (A > 0)
    out = np.zeros(A.shape)
    out[ok] = (Fy[ok] / A[ok]) ** (1.0 / n[ok])
    return out


def initial_state(A, n, F_static, d_static, terms: YieldTerms) -> tuple:
    """(state, d0, hold_work): the kernels' state (STATE_ROWS, contacts) before the shot, the
    static overlaps d0 (m) and the plastic work the hold took (J, per contact; before the
    shot, so not in the shot's energy), for contacts of constants A (N/m^n), exponents n,
    static forces F_static (N) and elastic static overlaps d_static (m). Without a hold the
    contacts are as new (A_p = A, delta_p = 0) at d_static; with one, each contact loaded
    past its static yield (static_ratio x the rate law's pressure at the hold's rate
    r_hold = d_static / hold) rests flattened on its elastic curve through (delta*, F_static),
    at delta* > d_static."""
    A, n, F, d0 = (np.array(x, float) for x in np.broadcast_arrays(A, n, F_static, d_static))
    state = np.zeros((len(STATE_ROWS),) + A.shape)
    dy = yield_overlap(A, terms.yield_force, n)
    state[AP], state[DY], state[DYREF] = A, dy, dy
    work = np.zeros(A.shape)
    if terms.hold > 0 and terms.yield_force > 0:
        rate = np.maximum(d0 / terms.hold / terms.reference_rate, RATE_FLOOR)
        dys = dy * terms.static_ratio**2 * rate ** (2.0 * terms.rate_exponent)
        flat = (dys > 0) & (F > A * np.where(dys > 0, dys, 0.0) ** n)
        if np.any(flat):
            a, m, f, y = A[flat], n[flat], F[flat], dys[flat]
            fy = a * y**m
            ky = m * fy / y
            d_star = y + (f - fy) / ky
            de = m * f / (ky * np.sqrt((2.0 * f + fy) / (3.0 * fy)))
            state[DP][flat], state[AP][flat] = d_star - de, f / de**m
            work[flat] = a * y**(m + 1.0) / (m + 1.0) + 0.5 * (fy + f) * (d_star - y) - f * de / (m + 1.0)
            d0[flat] = d_star
    return state, d0, work


LAW = ContactLaw(
    "thornton",
    "elastic-plastic with memory (Thornton, J. Appl. Mech. 64, 383 (1997)): elastic A delta^n up to the yield "
    "force chain.yield_force, then the tangent line; unloading and reloading elastic with the enlarged radius "
    "and the permanent overlap; the yield pressure rises as (rate / chain.yield_reference_rate)^"
    "chain.yield_rate_exponent; chain.static_hold seconds of the magnet's load flatten the contacts before the "
    "shot at static_yield_ratio x that yield; an optional linear dashpot chain.contact_damping beside it",
    (YIELD_FORCE, RATE_EXPONENT, REFERENCE_RATE, STATIC_RATIO, STATIC_HOLD, dashpot.CONTACT_DAMPING),
    viscous_terms, PLASTIC, yield_terms)
