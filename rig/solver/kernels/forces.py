"""Contact forces, their time derivatives and the energy of the chain (numba)."""
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
def energy(u, v, mass, bias, A, d0):
    """Kinetic + Hertz elastic + potential of the constant loads (J).

    E = sum m v^2 / 2 + sum (2/5) A d^(5/2) - sum m b u, where m b is each body's constant
    external force (gravity, the magnet's force at t = 0).
    """
    nb = u.shape[0]
    e = 0.0
    for i in range(nb):
        e += 0.5 * mass[i] * v[i] * v[i] - mass[i] * bias[i] * u[i]
    for i in range(1, nb):
        d = d0[i] + u[i - 1] - u[i]
        if d > 0.0:
            e += 0.4 * A[i] * d * d * math.sqrt(d)
    return e


@jit
def momentum(v, mass):
    """Total linear momentum sum m v (kg m/s); the wall (mass 0 here) does not count."""
    p = 0.0
    for i in range(v.shape[0]):
        p += mass[i] * v[i]
    return p


@jit
def max_overlap_excess(u, d0, d_limit):
    """Largest d / d_limit over the contacts (> 1 means an overlap no real contact reaches)."""
    worst = 0.0
    for i in range(1, u.shape[0]):
        r = (d0[i] + u[i - 1] - u[i]) / d_limit[i]
        if r > worst or r != r:
            worst = r if r == r else math.inf
    return worst
