"""Dissipation (numba): the contacts' viscous terms and the holder's drag and friction, as
a flow of the velocities alone, split from the elastic chain.

A dissipative chain takes each step as

    E(dt/2)  S(dt)  E(dt/2)        (Strang splitting: second order in the dissipation)

with S the method's elastic step (the contacts' A d^n, every velocity synchronised at its
end) and E the flow of dv/dt = what dissipates, at fixed positions:

- each closed contact's viscous force g = c d' (c = mu + A tau d^(n-1),
  forces.viscous_coefficient), never more pulling than the elastic force pushes
  (g >= -A d^n, so the whole contact force never attracts), taken by explicit midpoint
  (second-order Runge-Kutta) substeps short enough to be stable (``substeps``);
- each bead's drag and Coulomb friction (rig.model.apparatus.Holder), by their exact flows
  (``holder_flow``);

E(t) = H(t/2) V(t) H(t/2), H the holder's flow and V the contacts'. E moves no body, so
the energy it takes is the kinetic energy it removes, counted exactly; its impulse on the
wall (a contact's viscous force on an immovable body) joins the wall's.

Arrays are (bodies, shots), as in the batched kernel; the single-shot kernel passes
(bodies, 1) views, so both do the same operations.
"""
import math

from instruments.jit import jit
from rig.solver.kernels.forces import power, viscous_coefficient


@jit
def holder_flow(v, gamma, a, slip, t):
    """Velocity (m/s) after t seconds of dv/dt = -gamma v - a tanh(v / slip) (the holder's
    drag rate gamma (1/s) and friction deceleration a (m/s^2)): the exact flows of the two
    terms composed symmetrically, drag t/2, friction t, drag t/2. Friction's exact flow:
    sinh(v/slip) decays as exp(-a t / slip); at |v| >> slip, |v| falls by a t."""
    if gamma > 0.0:
        v = v * math.exp(-0.5 * gamma * t)
    if a > 0.0:
        x = abs(v) / slip
        k = a * t / slip
        if x - k > 20.0:
            y = x - k + math.log1p(-math.exp(-2.0 * x))
        else:
            y = math.asinh(0.5 * math.exp(x - k) - 0.5 * math.exp(-x - k))
        v = math.copysign(y * slip, v)
    if gamma > 0.0:
        v = v * math.exp(-0.5 * gamma * t)
    return v


@jit
def _holder(v, onsite, slip, t):
    """Every body's velocity after t seconds of the holder's flow (onsite: (2, bodies,
    shots) drag rates and friction decelerations)."""
    for i in range(v.shape[0]):
        for s in range(v.shape[1]):
            if onsite[0, i, s] > 0.0 or onsite[1, i, s] > 0.0:
                v[i, s] = holder_flow(v[i, s], onsite[0, i, s], onsite[1, i, s], slip, t)


@jit
def _viscous(v, c, el, g):
    """g[i, s]: each slot's viscous force (N) at velocities v, c d' clipped at -el (the
    coefficients c and elastic forces el of the fixed positions)."""
    for i in range(1, v.shape[0]):
        for s in range(v.shape[1]):
            gi = c[i, s] * (v[i - 1, s] - v[i, s])
            g[i, s] = gi if gi > -el[i, s] else -el[i, s]


@jit
def _contacts(u, v, invm, A, d0, con, t, n, wall_slot, work, j_wall):
    """V(t): n explicit midpoint substeps of the contacts' viscous flow; j_wall[s] += the
    viscous impulse on the wall (N s). work: (4, bodies + 1, shots)."""
    c, el, g, v_half = work[0], work[1], work[2], work[3]
    nb = u.shape[0]
    for s in range(u.shape[1]):
        g[0, s] = 0.0
        g[nb, s] = 0.0
    for i in range(1, nb):
        for s in range(u.shape[1]):
            d = d0[i, s] + u[i - 1, s] - u[i, s]
            c[i, s] = viscous_coefficient(d, A[i, s], con[0, i, s], con[1, i, s], con[2, i, s])
            el[i, s] = A[i, s] * power(d, con[0, i, s]) if d > 0.0 else 0.0
    h = t / n
    for _ in range(n):
        _viscous(v, c, el, g)
        for i in range(nb):
            for s in range(u.shape[1]):
                v_half[i, s] = v[i, s] + 0.5 * h * (g[i, s] - g[i + 1, s]) * invm[i, s]
        _viscous(v_half, c, el, g)
        for i in range(nb):
            for s in range(u.shape[1]):
                v[i, s] += h * (g[i, s] - g[i + 1, s]) * invm[i, s]
        if wall_slot > 0:
            for s in range(u.shape[1]):
                j_wall[s] += h * g[wall_slot, s]


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
def dissipate(u, v, mass, invm, A, d0, con, onsite, slip, viscous, rate, t, wall_slot, work, lost, j_wall,
              j_holder):
    """E(t) (module doc) on every shot: lost[s] += the kinetic energy it takes (J),
    j_wall[s] += its impulse on the wall, j_holder[s] += the holder's impulse (N s).
    viscous: whether any contact has viscous terms; rate: the bound of ``substeps``."""
    _book(v, mass, 1.0, lost, j_holder)
    _holder(v, onsite, slip, 0.5 * t)
    if viscous:
        for s in range(v.shape[1]):  # the contacts' flow conserves momentum but for the wall's share
            j_holder[s] -= j_wall[s]
        _contacts(u, v, invm, A, d0, con, t, substeps(t, rate), wall_slot, work, j_wall)
        for s in range(v.shape[1]):
            j_holder[s] += j_wall[s]
    _holder(v, onsite, slip, 0.5 * t)
    _book(v, mass, -1.0, lost, j_holder)
