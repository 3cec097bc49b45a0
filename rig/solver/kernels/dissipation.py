"""Dissipation (numba): the contacts' viscous terms and the holder's drag and friction, as
a flow of the velocities alone, split from the elastic chain.

A dissipative chain takes each step as

    E(dt/2)  S(dt)  E(dt/2)        (Strang splitting: second order in the dissipation)

with S the method's elastic step (the contacts' A d^n, every velocity synchronised at its
end) and E the flow of dv/dt = what dissipates, at fixed positions:

- each closed contact's viscous force g = c d' (c = mu + A tau d^(n-1),
  forces.viscous_coefficient), never more pulling than the elastic force pushes
  (g >= -A d^n, so the whole contact force never attracts; a contact with memory, PLASTIC,
  is closed while d > d_p and pushes rig.model.laws.thornton.plastic_force), taken by explicit
  midpoint
  (second-order Runge-Kutta) substeps short enough to be stable (``substeps``);
- with a power-law dashpot (exponent alpha != 1), g = A tau d^(n-1) d' + mu |d'|^alpha
  sgn d', whose coefficient c = A tau d^(n-1) + mu |d'|^(alpha-1) depends on the rate and,
  for alpha < 1, grows without bound as d' -> 0 (the exact flow stops a lone contact's
  relative motion in a finite time). The substeps' count takes c at the striker's speed
  (stepsize.viscous_rate); each substep holds every contact's c to at most
  1 / (2 h (1/m_1 + 1/m_2)) (h the substep, m_1, m_2 its bodies), where the midpoint rule
  of the frozen coefficients is stable (Gershgorin: h x rate <= 2) and takes at most half
  of a lone contact's relative speed: near d' = 0 the relative speed then decays
  geometrically, substep by substep, instead of reversing (the flow's stop, to within a
  speed (2 h mu (1/m_1 + 1/m_2))^(1/(1-alpha)) that vanishes with h);
- each bead's drag and Coulomb friction (rig.model.apparatus.Holder), by their exact flows
  (``holder_flow``);

E(t) = H(t/2) V(t) H(t/2), H the holder's flow and V the contacts' (without viscous
contacts E(t) = H(t), one pass over the bodies). E moves no body, so
the energy it takes is the kinetic energy it removes, counted exactly; its impulse on the
wall (a contact's viscous force on an immovable body) joins the wall's.

Arrays are (bodies, shots), as in the batched kernel; the single-shot kernel passes
(bodies, 1) views, so both do the same operations.
"""
import math

import numpy as np

from numerics.jit import jit
from rig.model.contact import PLASTIC
from rig.model.laws.thornton import DP, plastic_force
from rig.solver.kernels.forces import power, viscous_coefficient


@jit
def holder_flow(v, half_decay, a, slip, t):
    """Velocity (m/s) after t seconds of dv/dt = -gamma v - a tanh(v / slip) (the holder's
    drag rate gamma (1/s), given as half_decay = e^(-gamma t / 2), and friction deceleration
    a (m/s^2)): the exact flows of the two terms composed symmetrically, drag t/2, friction
    t, drag t/2. Friction's exact flow: sinh(v/slip) decays as exp(-a t / slip); at
    |v| >> slip, |v| falls by a t."""
    v = v * half_decay
    if a > 0.0:
        x = abs(v) / slip
        k = a * t / slip
        if x - k > 20.0:
            y = x - k + math.log1p(-math.exp(-2.0 * x))
        else:
            y = math.asinh(0.5 * math.exp(x - k) - 0.5 * math.exp(-x - k))
        v = math.copysign(y * slip, v)
    return v * half_decay


@jit
def holder_factors(onsite, t_flow, viscous):
    """(2, bodies, shots): each body's half_decay e^(-gamma t / 2) (holder_flow) for the
    holder flows of ``dissipate(..., t_flow, ...)`` (t = t_flow / 2 with viscous contacts,
    else t_flow), and its friction deceleration (m/s^2), from onsite (2, bodies, shots):
    drag rates gamma (1/s) and friction decelerations. The exponentials once per solve
    instead of twice per body per flow."""
    t = 0.5 * t_flow if viscous else t_flow
    out = np.empty_like(onsite)
    for i in range(onsite.shape[1]):
        for s in range(onsite.shape[2]):
            out[0, i, s] = math.exp(-0.5 * onsite[0, i, s] * t)
            out[1, i, s] = onsite[1, i, s]
    return out


@jit
def _holder(v, mass, hold, slip, t, lost, j_holder):
    """Every body's velocity after t seconds of the holder's flow (hold: holder_factors of
    t); lost[s] += the kinetic energy it took (J), j_holder[s] += the momentum it gave (N s)."""
    for i in range(v.shape[0]):
        for s in range(v.shape[1]):
            if hold[0, i, s] != 1.0 or hold[1, i, s] > 0.0:
                v0 = v[i, s]
                v1 = holder_flow(v0, hold[0, i, s], hold[1, i, s], slip, t)
                v[i, s] = v1
                lost[s] += 0.5 * mass[i, s] * (v0 - v1) * (v0 + v1)
                j_holder[s] += mass[i, s] * (v1 - v0)


@jit
def _viscous(v, c, el, g, w, m):
    """g[k]: each slot's viscous force (N) at velocities v, c d' clipped at -el (the
    coefficients c and elastic forces el of the fixed positions). Flat (bodies x shots)
    arrays: slot k joins bodies k - w and k (w shots per row); k from w to m."""
    for k in range(np.uint64(w), np.uint64(m)):
        gi = c[k] * (v[k - w] - v[k])
        g[k] = gi if gi > -el[k] else -el[k]


@jit
def _viscous_power(v, c, dash, alpha, im, h, el, g, w, m):
    """g[k]: each slot's viscous force (N) at velocities v with power-law dashpots (module
    doc): (c + dash |r|^(alpha-1)) r, r the slot's closing rate, its coefficient held to at
    most 1 / (2 h (invm above + invm below)), clipped at -el (c: Kuwabara-Kono's
    coefficients, dash: the dashpots' mu where closed, 0 where open). Flat arrays as in _viscous."""
    for k in range(np.uint64(w), np.uint64(m)):
        r = v[k - w] - v[k]
        a = abs(r)
        ck = c[k] + dash[k] * a ** (alpha[k] - 1.0) if a > 0.0 else c[k]
        stiff = 2.0 * h * ck * (im[k - w] + im[k])
        if stiff > 1.0:
            ck = ck / stiff
        gi = ck * r
        g[k] = gi if gi > -el[k] else -el[k]


@jit
def _contacts(u, v, invm, A, d0, con, law, state, t, n, wall_slot, work, j_wall):
    """V(t): n explicit midpoint substeps of the contacts' viscous flow; j_wall[s] += the
    viscous impulse on the wall (N s). work: (5, bodies + 1, shots). The (bodies, shots)
    arrays are C-contiguous and taken flat, row after row, so that the loops vectorise."""
    nb, W = u.shape
    w = np.uint64(W)
    m = nb * W
    uf, vf, im, Af, d0f = u.reshape(m), v.reshape(m), invm.reshape(m), A.reshape(m), d0.reshape(m)
    ex, tau, mu, alpha = con[0].reshape(m), con[1].reshape(m), con[2].reshape(m), con[3].reshape(m)
    size = (nb + 1) * W
    c, el, g, v_half = work[0].reshape(size), work[1].reshape(size), work[2].reshape(size), work[3].reshape(size)
    dash = work[4].reshape(size)
    nonlinear = False
    for k in range(w, np.uint64(m)):
        nonlinear = nonlinear or (alpha[k] != 1.0 and mu[k] != 0.0)
    g[:W] = 0.0
    g[m:] = 0.0
    for k in range(w, np.uint64(m)):  # every slot as Hertz's (vectorised square roots), then the others
        d = d0f[k] + uf[k - w] - uf[k]
        dp = d if d > 0.0 else 0.0
        r = math.sqrt(dp)
        c[k] = mu[k] + Af[k] * tau[k] * r if d > 0.0 else 0.0
        el[k] = Af[k] * dp * r
    for k in range(w, np.uint64(m)):
        if ex[k] != 1.5:
            d = d0f[k] + uf[k - w] - uf[k]
            c[k] = viscous_coefficient(d, Af[k], ex[k], tau[k], mu[k])
            el[k] = Af[k] * power(d, ex[k]) if d > 0.0 else 0.0
    if law == PLASTIC:  # closed while d > d_p, pushing thornton.plastic_force (a dashpot alone: tau = 0)
        for i in range(1, nb):
            for s in range(W):
                d = d0[i, s] + u[i - 1, s] - u[i, s]
                k = i * W + s
                c[k] = mu[k] if d > state[DP, i, s] else 0.0
                el[k] = plastic_force(d, A[i, s], con[0, i, s], state, i, s)
    if nonlinear:  # c: Kuwabara-Kono's part alone, the dashpots apart
        for k in range(w, np.uint64(m)):
            d = d0f[k] + uf[k - w] - uf[k]
            c[k] = viscous_coefficient(d, Af[k], ex[k], tau[k], 0.0)
            dash[k] = mu[k] if d > 0.0 else 0.0
    h = t / n
    for _ in range(n):
        if nonlinear:
            _viscous_power(vf, c, dash, alpha, im, h, el, g, w, m)
        else:
            _viscous(vf, c, el, g, w, m)
        for k in range(np.uint64(m)):
            v_half[k] = vf[k] + 0.5 * h * (g[k] - g[k + w]) * im[k]
        if nonlinear:
            _viscous_power(v_half, c, dash, alpha, im, h, el, g, w, m)
        else:
            _viscous(v_half, c, el, g, w, m)
        for k in range(np.uint64(m)):
            vf[k] += h * (g[k] - g[k + w]) * im[k]
        if wall_slot > 0:
            for s in range(W):
                j_wall[s] += h * g[wall_slot * W + s]


@jit
def substeps(t, rate):
    """Midpoint substeps of the contacts' viscous flow over t seconds: at most 1 / rate s
    each (rate: a bound on the flow's largest decay rate, 1/s), where the midpoint rule is
    stable (it needs rate x substep <= 2) and accurate."""
    return max(1, int(math.ceil(t * rate)))


@jit
def _book(v, mass, sign, lost, j_holder):
    """lost[s] += sign x each shot's kinetic energy (J), j_holder[s] -= sign x its momentum
    (N s): taken before the flow (sign 1) and after it (sign -1), what the flow removed."""
    for s in range(v.shape[1]):
        ke = 0.0
        p = 0.0
        for i in range(v.shape[0]):
            ke += 0.5 * mass[i, s] * v[i, s] * v[i, s]
            p += mass[i, s] * v[i, s]
        lost[s] += sign * ke
        j_holder[s] -= sign * p


@jit
def dissipate(u, v, mass, invm, A, d0, con, law, state, hold, slip, viscous, holder, rate, t, wall_slot, work, lost,
              j_wall, j_holder):
    """E(t) (module doc) on every shot: lost[s] += the kinetic energy it takes (J),
    j_wall[s] += its impulse on the wall, j_holder[s] += the holder's impulse (N s).
    viscous: whether any contact has viscous terms; holder: whether any body has drag or
    friction; rate: the bound of ``substeps``; hold: holder_factors(onsite, t, viscous)
    (H(t/2) V(t) H(t/2) with viscous contacts, else E(t) = H(t), one pass); law, state: the
    contacts' code and memory (PLASTIC: closed while d > d_p)."""
    if not viscous:
        _holder(v, mass, hold, slip, t, lost, j_holder)
        return
    if holder:
        _holder(v, mass, hold, slip, 0.5 * t, lost, j_holder)
    _book(v, mass, 1.0, lost, j_holder)
    for s in range(v.shape[1]):  # the contacts' flow conserves momentum but for the wall's share
        j_holder[s] -= j_wall[s]
    _contacts(u, v, invm, A, d0, con, law, state, t, substeps(t, rate), wall_slot, work, j_wall)
    for s in range(v.shape[1]):
        j_holder[s] += j_wall[s]
    _book(v, mass, -1.0, lost, j_holder)
    if holder:
        _holder(v, mass, hold, slip, 0.5 * t, lost, j_holder)
