"""The multirate head (numba): the flow of the first ``head`` contacts inside a drift.

Arrays are (bodies, shots); the single-shot kernel passes (bodies, 1) views, so both
kernels perform the same operations. Bodies 0..head move under their own contacts
(slots 1..head, Hertz, constant loads folded in as in forces.contact_forces) by ``n``
substeps of h / n seconds of the same kick-drift composition as the outer method
(coefficients a, b; the closing kick of a substep merged into the next one's first). h
may be negative: some drifts of a composition go backwards. The head's slot forces in f
are current on entry and on exit.
"""
import math

from numba import njit


@njit(cache=True, fastmath=False)
def _head_kick(v, invm, f, head, hk):
    for i in range(head + 1):
        for s in range(v.shape[1]):
            below = f[i + 1, s] if i < head else 0.0
            v[i, s] += hk * (f[i, s] - below) * invm[i, s]


@njit(cache=True, fastmath=False)
def head_flow(u, v, invm, f, A, d0, load, head, a_coef, b_coef, h, n):
    """Advance every shot's head by h seconds in n substeps (u, v, f in place)."""
    k = h / n
    n_drift = a_coef.shape[0]
    pending = 0.0
    for _ in range(n):
        for st in range(n_drift):
            _head_kick(v, invm, f, head, b_coef[st] * k + pending)
            pending = 0.0
            ha = a_coef[st] * k
            for i in range(head + 1):
                for s in range(u.shape[1]):
                    u[i, s] += ha * v[i, s]
            for i in range(1, head + 1):
                for s in range(u.shape[1]):
                    d = d0[i, s] + u[i - 1, s] - u[i, s]
                    d = d if d > 0.0 else 0.0
                    f[i, s] = A[i, s] * d * math.sqrt(d) - load[i, s]
        pending = b_coef[n_drift] * k
    _head_kick(v, invm, f, head, pending)


@njit(cache=True, fastmath=False)
def slow_net(f, j, head, s):
    """Net force on body j from the slots the method's kicks carry (all but the head's)."""
    if head == 0:
        return f[j, s] - f[j + 1, s]
    above = f[j, s] if j > head else 0.0
    below = f[j + 1, s] if j + 1 > head else 0.0
    return above - below
