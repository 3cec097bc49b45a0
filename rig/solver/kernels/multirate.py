"""The multirate head (numba): the flow of the first ``head`` contacts inside a drift.

Arrays are (bodies, shots); the single-shot kernel passes (bodies, 1) views, so both
kernels perform the same operations. Bodies 0..head move under their own contacts
(slots 1..head, Hertz, constant loads folded in as in forces.contact_forces) by ``n``
substeps of h / n seconds of the same kick-drift composition as the outer method
(coefficients a, b; the closing kick of a substep merged into the next one's first). h
may be negative: some drifts of a composition go backwards. The head's slot forces in f
are current on entry and on exit.

While every head contact is open the head's bodies feel constant forces (the loads), and
their flow is known exactly: a shot whose head contacts are open and provably stay open
for the whole drift takes it in closed form instead of n substeps (a striker is in
contact with the chain for about 12 us of a 3 ms shot). The proof bounds each gap over
the drift: with gap g, its rate g' and its constant second derivative g'',

    g - |g'| |h| sum|a_s| - |g''| h^2 sum|a_s| sum|b_s| > 0

keeps it open over the drift, with room to spare (sum|a_s| >= 1). The choice is made per
shot from its own state, the same in both kernels.
"""
import math

from instruments.jit import jit


@jit
def _open_acceleration(j, invm, load, head, s):
    """Acceleration of head body j (m/s^2) while every head contact is open: the loads only."""
    above = -load[j, s] if j > 0 else 0.0
    below = -load[j + 1, s] if j < head else 0.0
    return (above - below) * invm[j, s]


@jit
def _substeps(u, v, invm, d0, load, head, a_coef, b_coef, h, n, ns):
    """ns[s]: 0 where shot s's head contacts are open and stay open through the drift (its
    flow is then taken in closed form), else the n substeps (bound in the module doc)."""
    sum_a = 0.0
    for a in a_coef:
        sum_a += abs(a)
    sum_b = 0.0
    for b in b_coef:
        sum_b += abs(b)
    reach = abs(h) * sum_a
    spread = h * h * sum_a * sum_b
    for s in range(u.shape[1]):
        ns[s] = 0
    for i in range(1, head + 1):
        for s in range(u.shape[1]):  # no branch on the shot: this loop vectorises
            gap = -(d0[i, s] + u[i - 1, s] - u[i, s])
            rate = v[i, s] - v[i - 1, s]
            curv = (_open_acceleration(i, invm, load, head, s)
                    - _open_acceleration(i - 1, invm, load, head, s))
            ns[s] = ns[s] if gap - abs(rate) * reach - abs(curv) * spread > 0.0 else n


@jit
def head_flow(u, v, invm, f, A, d0, load, head, a_coef, b_coef, h, n, ns, work):
    """Advance every shot's head by h seconds (u, v, f in place): n substeps where a head
    contact is or may come closed; elsewhere the exact flow under the constant loads,
    u += h v + h^2 a / 2, v += h a (the forces stay -load). Work arrays, one entry per
    shot: ns (int64) and work (3, shots); every loop is free of branches on the shot."""
    _substeps(u, v, invm, d0, load, head, a_coef, b_coef, h, n, ns)
    step, on, pending = work[0], work[1], work[2]
    n_drift = a_coef.shape[0]
    most = 0
    for s in range(u.shape[1]):
        most = max(most, ns[s])
        on[s] = 1.0 if ns[s] > 0 else 0.0
        step[s] = h / ns[s] if ns[s] > 0 else 0.0  # the free ones idle through the substeps
        pending[s] = 0.0
    if most > 0:
        for _ in range(most):
            for st in range(n_drift):
                for i in range(head + 1):
                    for s in range(u.shape[1]):
                        below = f[i + 1, s] if i < head else 0.0
                        v[i, s] += (b_coef[st] * step[s] + pending[s] * on[s]) * (f[i, s] - below) * invm[i, s]
                for s in range(u.shape[1]):
                    pending[s] = pending[s] * (1.0 - on[s])
                for i in range(head + 1):
                    for s in range(u.shape[1]):
                        u[i, s] += a_coef[st] * step[s] * v[i, s]
                for i in range(1, head + 1):
                    for s in range(u.shape[1]):
                        d = d0[i, s] + u[i - 1, s] - u[i, s]
                        d = d if d > 0.0 else 0.0
                        f[i, s] = A[i, s] * d * math.sqrt(d) - load[i, s]
            for s in range(u.shape[1]):
                pending[s] = pending[s] + b_coef[n_drift] * step[s]
        for i in range(head + 1):
            for s in range(u.shape[1]):
                below = f[i + 1, s] if i < head else 0.0
                v[i, s] += pending[s] * (f[i, s] - below) * invm[i, s]
    for i in range(head + 1):
        for s in range(u.shape[1]):
            below = f[i + 1, s] if i < head else 0.0
            acc = (f[i, s] - below) * invm[i, s]
            free = 1.0 - on[s]
            u[i, s] += free * (h * v[i, s] + 0.5 * h * h * acc)
            v[i, s] += free * (h * acc)


@jit
def slow_net(f, j, head, s):
    """Net force on body j from the slots the method's kicks carry (all but the head's)."""
    if head == 0:
        return f[j, s] - f[j + 1, s]
    above = f[j, s] if j > head else 0.0
    below = f[j + 1, s] if j + 1 > head else 0.0
    return above - below
