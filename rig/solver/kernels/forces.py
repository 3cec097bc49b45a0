"""Contact forces, the holder's on-site forces and the chain's energy, momentum and largest
overlap (numba).

A contact at overlap d (m) closing at rate r = d' (m/s) pushes its two bodies apart with

    HERTZ          F = A d^(3/2)
    KUWABARA_KONO  F = max(A d^(1/2) (d + tau r) + mu r, 0)      (Hertz with viscous terms)
    POWER          F = max(A d^(n-1) (d + tau r) + mu r, 0)      (any exponent n per contact)

for d > 0, and 0 otherwise (rig.model.contact: tau the Kuwabara-Kono damping time, mu a
dashpot). Its elastic part is A d^n, its energy A d^(n+1) / (n+1); the rest, c r with
c = mu + A tau d^(n-1), is viscous (dissipation.py integrates it). The law code is the
problem's (rig.solver.problem.kernel_law): the kernels' force passes carry the elastic
part, by the Hertz loops wherever every exponent is 3/2.
"""
import math

from instruments.jit import jit
from rig.model.contact import HERTZ, KUWABARA_KONO, POWER


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


@jit
def contact_force(d, rate, A, n, tau, mu, law):
    """(F, its elastic part) (N) of one contact at overlap d (m), closing at rate (m/s),
    by the law of code ``law`` (module doc)."""
    d = d if d > 0.0 else 0.0
    if law == HERTZ:
        el = A * d * math.sqrt(d)
        return el, el
    if law == KUWABARA_KONO:
        s = math.sqrt(d)
        fi = A * s * (d + tau * rate) + (mu * rate if d > 0.0 else 0.0)
        return (fi if fi > 0.0 else 0.0), A * s * d
    p = power(d, n)
    el = A * p
    fi = A * (p + tau * rate * (p / d if d > 0.0 else 0.0)) + (mu * rate if d > 0.0 else 0.0)
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
    c d'); 0 for d <= 0."""
    if not d > 0.0:
        return 0.0
    if tau == 0.0:
        return mu
    return mu + A * tau * (math.sqrt(d) if n == 1.5 else d ** (n - 1.0))


@jit
def elastic_forces(u, A, d0, load, f, law, expo):
    """Fill f[1:nb] with the dynamic elastic contact forces (N): A d^n minus ``load``.

    load[i] is the constant external force carried from above through slot i (the weight
    and magnet force of bodies 0..i-1), so that body i is pushed by f[i] - f[i+1] alone
    (its own constant load is load[i+1] - load[i]) and a chain at rest has f = 0.
    Hertz: A d^(3/2), d = max(d0[i] + u[i-1] - u[i], 0), branch-free so that LLVM
    vectorises the square roots; POWER: that pass, then other_law's.
    """
    hertz_forces(u, A, d0, load, f)
    if law == POWER:
        other_law(u, A, d0, load, f, expo, 1, u.shape[0])


@jit(error_model="numpy")  # a division by zero gives inf (no check per element, which stops vectorising)
def state_sums(u, v, mass, bias, A, expo, d0, d_limit, law, e, p, w):
    """Each shot's energy e (J), momentum p (kg m/s) and largest d / d_limit w (> 1: an
    overlap no real contact reaches; inf for nan), arrays (bodies, shots), in two passes:

        E = sum m v^2 / 2 + sum A d^(n+1) / (n+1) - sum m b u,   P = sum m v,

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
        if law != POWER:  # the exponent a literal: no branch on the data, the loop vectorises
            for s in range(u.shape[1]):
                e[s] += elastic_energy(d0[i, s] + u[i - 1, s] - u[i, s], A[i, s], 1.5)
        else:
            for s in range(u.shape[1]):
                e[s] += elastic_energy(d0[i, s] + u[i - 1, s] - u[i, s], A[i, s], expo[i, s])
        for s in range(u.shape[1]):
            q = (d0[i, s] + u[i - 1, s] - u[i, s]) / d_limit[i, s]
            w[s] = max(w[s], q) if q == q else math.inf
