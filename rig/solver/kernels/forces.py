"""Contact forces and the chain's energy, momentum and largest overlap (numba)."""
import math

from instruments.jit import jit
from rig.model.contact import HERTZ


@jit
def contact_forces(u, v, A, d0, damping, law, load, f):
    """Fill f[1:nb] with the dynamic contact forces (N): contact force minus ``load``.

    load[i] is the constant external force carried from above through slot i (the weight
    and magnet force of bodies 0..i-1), so that body i is pushed by f[i] - f[i+1] alone
    (its own constant load is load[i+1] - load[i]) and a chain at rest has f = 0.
    Hertz: A d^(3/2), d = max(d0[i] + u[i-1] - u[i], 0), branch-free so that LLVM
    vectorises the square roots. Kuwabara-Kono adds A d^(1/2) tau_d d(d)/dt and clips the
    contact force at zero (no attraction).
    """
    nb = u.shape[0]
    if law == HERTZ:
        for i in range(1, nb):
            d = d0[i] + u[i - 1] - u[i]
            d = d if d > 0.0 else 0.0
            f[i] = A[i] * d * math.sqrt(d) - load[i]
    else:
        for i in range(1, nb):
            d = d0[i] + u[i - 1] - u[i]
            d = d if d > 0.0 else 0.0
            fi = A[i] * math.sqrt(d) * (d + damping[i] * (v[i - 1] - v[i]))
            f[i] = (fi if fi > 0.0 else 0.0) - load[i]


@jit
def state_sums(u, v, mass, bias, A, d0, d_limit, e, p, w):
    """Each shot's energy e (J), momentum p (kg m/s) and largest d / d_limit w (> 1: an
    overlap no real contact reaches; inf for nan), arrays (bodies, shots), in two passes:

        E = sum m v^2 / 2 + sum (2/5) A d^(5/2) - sum m b u,   P = sum m v,

    m b each body's constant external force (gravity, the magnet's force at t = 0); the
    wall (mass 0 here) counts for neither."""
    nb = u.shape[0]
    e[:] = 0.0
    p[:] = 0.0
    w[:] = 0.0
    for i in range(nb):
        for s in range(u.shape[1]):
            e[s] += 0.5 * mass[i, s] * v[i, s] * v[i, s] - mass[i, s] * bias[i, s] * u[i, s]
            p[s] += mass[i, s] * v[i, s]
    for i in range(1, nb):
        for s in range(u.shape[1]):
            d = d0[i, s] + u[i - 1, s] - u[i, s]
            if d > 0.0:
                e[s] += 0.4 * A[i, s] * d * d * math.sqrt(d)
            q = d / d_limit[i, s]
            w[s] = max(w[s], q) if q == q else math.inf
