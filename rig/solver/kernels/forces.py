"""Contact forces, the holder's on-site forces and the chain's energy, momentum and largest
overlap (numba).

A contact at overlap d (m) closing at rate r = d' (m/s) pushes its two bodies apart with

    HERTZ          F = A d^(3/2)
    KUWABARA_KONO  F = max(A d^(1/2) (d + tau r) + mu |r|^alpha sgn r, 0)   (Hertz with viscous terms)
    POWER          F = max(A d^(n-1) (d + tau r) + mu |r|^alpha sgn r, 0)   (any exponent n per contact)
    PLASTIC        F = max(F_p(d, r; memory) + mu r, 0)    (rig.model.laws.thornton, a linear dashpot beside)

for d > 0, and 0 otherwise (rig.model.laws: tau the Kuwabara-Kono damping time, mu a
dashpot's coefficient, alpha its exponent, 1 for a linear one). Its elastic part is A d^n,
its energy A d^(n+1) / (n+1); the rest, A tau d^(n-1) r + mu |r|^alpha sgn r, is viscous
(dissipation.py integrates it). A PLASTIC contact's elastic part is its present elastic
curve A_p (d - d_p)^n, which a yield renews (its memory, ``state``: rows
rig.model.laws.thornton.STATE_ROWS, (rows, slots, shots)). The law code is the problem's
(rig.solver.problem.kernel_law): the kernels' force passes carry the elastic part, by the
Hertz loops wherever every exponent is 3/2.
"""
import math

import numpy as np

from numerics.jit import jit
from rig.model.contact import HERTZ, KUWABARA_KONO, PLASTIC, POWER
from rig.model.laws.thornton import AP, DC, DP, DS, SPAN_END, SPAN_FIRST, plastic_energy, plastic_force


@jit(inline="always")
def power(d, n):
    """d^n for d >= 0: d sqrt(d) for Hertz's 3/2 and d for a linear spring, exactly."""
    if n == 1.5:
        return d * math.sqrt(d)
    if n == 1.0:
        return d
    return d**n


@jit
def other_law(u, A, d0, load, f, expo, lo, hi):
    """Renew slots lo..hi-1 whose exponent is not 3/2 by their own law, A d^n - load,
    after a Hertz pass renewed every slot from the same positions (a scalar pass: a pow per
    such slot; an exponent-3/2 slot keeps the Hertz pass's bits). Keeping the pow out of the
    Hertz loop keeps that loop vectorised: a chain with a few other slots (a compliant
    wall's linear rod) costs a Hertz pass and a scan."""
    for i in range(lo, hi):
        n = expo[i]
        if n != 1.5:
            d = d0[i] + u[i - 1] - u[i]
            f[i] = A[i] * power(d if d > 0.0 else 0.0, n) - load[i]


@jit(inline="always")
def dashpot_rate(rate, alpha):
    """|rate|^alpha sgn(rate) ((m/s)^alpha): the rate itself for a linear dashpot (alpha = 1), exactly."""
    if alpha == 1.0:
        return rate
    return math.copysign(abs(rate) ** alpha, rate)


@jit
def contact_force(d, rate, A, n, tau, mu, alpha, law):
    """(F, its elastic part) (N) of one contact at overlap d (m), closing at rate (m/s),
    by the law of code ``law`` (module doc)."""
    d = d if d > 0.0 else 0.0
    if law == HERTZ:
        el = A * d * math.sqrt(d)
        return el, el
    if law == KUWABARA_KONO:
        s = math.sqrt(d)
        fi = A * s * (d + tau * rate) + (mu * dashpot_rate(rate, alpha) if d > 0.0 else 0.0)
        return (fi if fi > 0.0 else 0.0), A * s * d
    p = power(d, n)
    el = A * p
    fi = A * (p + tau * rate * (p / d if d > 0.0 else 0.0)) + (mu * dashpot_rate(rate, alpha) if d > 0.0 else 0.0)
    return (fi if fi > 0.0 else 0.0), el


@jit
def open_span(state):
    """Every slot in every shot's span (rig/solver/kernels/memory.py), before a step's end
    has found the near ones."""
    for s in range(state.shape[2]):
        state[SPAN_FIRST, 0, s] = 1.0
        state[SPAN_END, 0, s] = state.shape[1]


@jit
def plastic_fixup(u, A, d0, load, f, expo, state, lo, hi):
    """After a Hertz pass that took each slot's elastic curve (A_p and d0 - delta_p for A and
    d0: thornton's DS row), renew the slots of lo..hi-1 (lo >= 1) of one shot that it does
    not give: those past their elastic limit (on the envelope) and those of another exponent,
    f[i] = F_p(d) - load[i] (thornton.plastic_force; state (rows, bodies, 1), held through the
    step). Only the slots of the shot's span are looked at (rig/solver/kernels/memory.py)."""
    first = max(lo, int(state[SPAN_FIRST, 0, 0]))
    end = min(hi, int(state[SPAN_END, 0, 0]))
    for i in range(first, end):
        d = d0[i] + u[i - 1] - u[i]
        if d > state[DC, i, 0] or expo[i] != 1.5:
            f[i] = plastic_force(d, A[i], expo[i], state, i, 0) - load[i]


@jit
def plastic_contact(d, rate, A, n, mu, state, i, s):
    """(F, its elastic-plastic part) (N) of a PLASTIC contact (module doc): the part by
    thornton.plastic_force, a dashpot mu r beside it while closed (d > d_p), never
    attractive."""
    el = plastic_force(d, A, n, state, i, s)
    fi = el + (mu * rate if d > state[DP, i, s] else 0.0)
    return (fi if fi > 0.0 else 0.0), el


@jit(inline="always")
def elastic_energy(d, A, n):
    """A d^(n+1) / (n+1) (J) for d > 0, else 0: (2/5) A d^(5/2) for Hertz."""
    if not d > 0.0:
        return 0.0
    if n == 1.5:
        return 0.4 * A * d * d * math.sqrt(d)
    return A * d * power(d, n) / (n + 1.0)


@jit
def hertz_forces(u, A, d0, load, f):
    """f[1:nb] = A d^(3/2) - load: elastic_forces' Hertz loop."""
    for i in range(1, u.shape[0]):
        d = d0[i] + u[i - 1] - u[i]
        d = d if d > 0.0 else 0.0
        f[i] = A[i] * d * math.sqrt(d) - load[i]


@jit(inline="always")
def viscous_coefficient(d, A, n, tau, mu):
    """c = mu + A tau d^(n-1) (kg/s) of a contact at overlap d > 0 (its viscous force is
    c d' with a linear dashpot mu); 0 for d <= 0."""
    if not d > 0.0:
        return 0.0
    if tau == 0.0:
        return mu
    return mu + A * tau * (math.sqrt(d) if n == 1.5 else d ** (n - 1.0))


@jit
def elastic_forces(u, A, d0, load, f, law, con, state):
    """Fill f[1:nb] with the dynamic elastic contact forces (N): A d^n minus ``load``.

    load[i] is the constant external force carried from above through slot i (the weight
    and magnet force of bodies 0..i-1), so that body i is pushed by f[i] - f[i+1] alone
    (its own constant load is load[i+1] - load[i]) and a chain at rest has f = 0.
    Hertz: A d^(3/2), d = max(d0[i] + u[i-1] - u[i], 0), branch-free so that LLVM
    vectorises the square roots; POWER: that pass, then other_law's; PLASTIC: that pass over
    each slot's elastic curve, then plastic_fixup's (con: the slots' CONTACT_ROWS, state their
    memory, (rows, bodies, 1)).
    """
    if law == PLASTIC:  # the elastic curves by the Hertz pass, then what it does not give, every slot
        hertz_forces(u, state[AP, :, 0].copy(), state[DS, :, 0].copy(), load, f)
        open_span(state)
        plastic_fixup(u, A, d0, load, f, con[0], state, 1, u.shape[0])
        return
    hertz_forces(u, A, d0, load, f)
    if law == POWER:
        other_law(u, A, d0, load, f, con[0], 1, u.shape[0])


@jit(error_model="numpy")  # a division by zero gives inf (no check per element, which stops vectorising)
def state_sums(u, v, mass, bias, A, expo, d0, d_limit, law, state, e, p, w):
    """Each shot's energy e (J), momentum p (kg m/s) and largest d / d_limit w (> 1: an
    overlap no real contact reaches; inf for nan), arrays (bodies, shots), in two passes:

        E = sum m v^2 / 2 + sum A d^(n+1) / (n+1) - sum m b u,   P = sum m v,

    (PLASTIC: each contact's potential plus the plastic work it took, thornton.plastic_energy
    of its memory ``state``)
    m b each body's constant external force (gravity, the magnet's force at t = 0); the
    wall (mass 0 here) counts for neither. An open contact adds +0, which leaves a sum
    unchanged. Where every exponent is 3/2 (law not POWER) the loop over the shots
    vectorises; the overlaps' ratios take a pass of their own (fused with the energies,
    neither loop vectorised)."""
    nb = u.shape[0]
    e[:] = 0.0
    p[:] = 0.0
    w[:] = 0.0
    for i in range(nb):
        for s in range(u.shape[1]):
            e[s] += 0.5 * mass[i, s] * v[i, s] * v[i, s] - mass[i, s] * bias[i, s] * u[i, s]
            p[s] += mass[i, s] * v[i, s]
    for i in range(1, nb):
        if law == PLASTIC:
            for s in range(u.shape[1]):
                e[s] += plastic_energy(d0[i, s] + u[i - 1, s] - u[i, s], A[i, s], expo[i, s], state, i, s)
        elif law != POWER:  # the exponent a literal: no branch on the data, the loop vectorises
            for s in range(u.shape[1]):
                e[s] += elastic_energy(d0[i, s] + u[i - 1, s] - u[i, s], A[i, s], 1.5)
        else:
            for s in range(u.shape[1]):
                e[s] += elastic_energy(d0[i, s] + u[i - 1, s] - u[i, s], A[i, s], expo[i, s])
        for s in range(u.shape[1]):
            q = (d0[i, s] + u[i - 1, s] - u[i, s]) / d_limit[i, s]
            w[s] = max(w[s], q) if q == q else math.inf


@jit(inline="always")
def rest_elastic(A, d0, n):
    """The elastic force (N) of a slot at rest (u = 0) by the force passes' own operations:
    (A d) sqrt(d) for Hertz, A d^n for other exponents, d = max(d0 + 0 - 0, 0)."""
    d = d0 + 0.0 - 0.0
    d = d if d > 0.0 else 0.0
    return A * d * math.sqrt(d) if n == 1.5 else A * power(d, n)


@jit(inline="always")
def _ulps(x, k):
    """x moved by k ulps (k > 0 up, < 0 down)."""
    for _ in range(abs(k)):
        x = np.nextafter(x, math.inf if k > 0 else -math.inf)
    return x


@jit(nogil=True)
def balance_at_rest(first, last, load, A, d0, expo, invm, tolerance, nudges):
    """rig.solver.problem.balance_at_rest's rounding, shot by shot (arrays (shots, ...)),
    of shots first..last-1 (without the GIL: the ranges run on threads): the open slots'
    loads rounded to multiples of the ulp of the shot's largest load, then, down the chain,
    each body meant to rest given a lower slot whose force at rest is its upper slot's bit
    for bit, d0 and load moved by at most ``nudges`` ulps each."""
    nb = A.shape[1]
    for s in range(first, last):
        top = 0.0
        for i in range(nb + 1):
            top = max(top, abs(load[s, i]))
        q = np.spacing(top)
        for i in range(nb):
            if d0[s, i] <= 0.0 and load[s, i] != 0.0:
                load[s, i] = np.rint(load[s, i] / q) * q  # np.round(x): numba compiles its decimals branch too
        target = rest_elastic(A[s, 0], d0[s, 0], expo[s, 0]) - load[s, 0]
        for i in range(nb - 1):
            el = rest_elastic(A[s, i + 1], d0[s, i + 1], expo[s, i + 1])
            f = el - load[s, i + 1]
            scale = max(abs(load[s, i]), abs(load[s, i + 1]))
            if invm[s, i] > 0.0 and f != target and abs(f - target) <= tolerance * scale:
                done = False
                for jj in range(2 * nudges + 1):
                    j = (jj + 1) // 2 * (1 if jj % 2 else -1)  # 0, 1, -1, 2, -2, ...
                    d = _ulps(d0[s, i + 1], j)
                    el = rest_elastic(A[s, i + 1], d, expo[s, i + 1])
                    base = el - target
                    for kk in range(2 * nudges + 1):
                        cand = _ulps(base, (kk + 1) // 2 * (1 if kk % 2 else -1))
                        if el - cand == target:
                            d0[s, i + 1] = d
                            load[s, i + 1] = cand
                            f = target
                            done = True
                            break
                    if done:
                        break
            target = f
