"""The multirate head (numba): the flow of the first ``head`` contacts inside a drift.

Arrays are (bodies, shots); the single-shot kernel passes (bodies, 1) views, so both
kernels perform the same operations. Bodies 0..head move under their own contacts
(slots 1..head, Hertz, constant loads folded in as in forces.contact_forces) by ``n``
substeps of h / n seconds of the same kick-drift composition as the outer method
(coefficients a, b; the closing kick of a substep merged into the next one's first). h
may be negative: some drifts of a composition go backwards. The head's slot forces in f
are current on entry and on exit.

Impacts are resolved. Where a head contact closes or opens, the force A d^(3/2) is not
smooth in time ((t - t0)^(3/2)), and a step across that instant makes an error of order
h^(5/2) whose size depends on where in the step the instant falls: an irregular error
that dominates everything else in a struck chain (the striker's impact, its rebound, its
later strikes). A substep in which any head contact changes state (tested after every
drift of the composition) is therefore taken again as REFINE substeps, and the one of
those in which the change happens as REFINE again: the step across the event is REFINE^2
times shorter, its error REFINE^5 times smaller.

While every head contact is open the head's bodies feel constant forces (the loads), and
their flow is known exactly: a shot whose head contacts are open and provably stay open
for the whole drift takes it in closed form instead of n substeps (a striker is in
contact with the chain for about 12 us of a 3 ms shot). The proof bounds each gap over
the drift: with gap g, its rate g' and its constant second derivative g'',

    g - |g'| |h| sum|a_s| - |g''| h^2 sum|a_s| sum|b_s| > 0

keeps it open over the drift, with room to spare (sum|a_s| >= 1). The choice is made per
shot from its own state, the same in both kernels.

The substeps of the shots that need them run together, the shots innermost: every store
a select on the shot's mask (busy, refined at the first level, at the second), so the
loops vectorise, and each shot still gets the operations of its own sequence of
substeps. The shots of a batch strike at about the same instant, so the masks are mostly
full; taken one shot at a time through scalar calls, the head cost a batched shot of
ptfe52_magnetic about as much as its force passes.

_busy and _resolved_substeps, each called once, by head_flow, are inlined into it: numba
links a callee's machine code into each caller's module and optimises it again, so each
level of calls costs its whole subtree's compile once more (0.7 s CPU for these two).
"""
import math

from numerics.jit import jit

REFINE = 16  # pieces of a substep across which a head contact opens or closes (two levels)


@jit(inline="always")
def _open_acceleration(j, invm, load, head, s):
    """Acceleration of head body j (m/s^2) while every head contact is open: the loads only."""
    above = -load[j, s] if j > 0 else 0.0
    below = -load[j + 1, s] if j < head else 0.0
    return (above - below) * invm[j, s]


@jit(inline="always")
def _busy(u, v, invm, d0, load, head, a_coef, b_coef, h, busy):
    """busy[s]: 1 where a head contact of shot s is closed or may close during a drift of h
    seconds, 0 where all are open and provably stay open (bound in the module doc); no
    branch on the shot, so the loop vectorises."""
    sum_a = 0.0
    for a in a_coef:
        sum_a += abs(a)
    sum_b = 0.0
    for b in b_coef:
        sum_b += abs(b)
    reach = abs(h) * sum_a
    spread = h * h * sum_a * sum_b
    for s in range(u.shape[1]):
        busy[s] = 0.0
    for i in range(1, head + 1):
        for s in range(u.shape[1]):
            gap = -(d0[i, s] + u[i - 1, s] - u[i, s])
            rate = v[i, s] - v[i - 1, s]
            curv = (_open_acceleration(i, invm, load, head, s)
                    - _open_acceleration(i - 1, invm, load, head, s))
            busy[s] = busy[s] if gap - abs(rate) * reach - abs(curv) * spread > 0.0 else 1.0


@jit
def _lane_substep(u, v, invm, f, A, d0, load, head, a_coef, b_coef, k, pending, active, changed, closed):
    """One step of k seconds of the composition on the head of every shot s with
    active[s] != 0 (the others' rows are left as they were), its first kick merged with
    the owed pending[s] seconds; changed[s] = 1 where a head contact opened or closed during
    it. closed: (head, shots) work array. The shots are innermost and every store is a
    select, so the loops vectorise; each shot gets the operations of a scalar substep."""
    W = u.shape[1]
    for i in range(1, head + 1):
        for s in range(W):
            closed[i - 1, s] = 1.0 if d0[i, s] + u[i - 1, s] - u[i, s] > 0.0 else 0.0
    for s in range(W):
        changed[s] = 0.0
    for st in range(a_coef.shape[0]):
        hk = b_coef[st] * k
        ha = a_coef[st] * k
        for i in range(head + 1):
            for s in range(W):
                hb = hk + pending[s] if st == 0 else hk
                below = f[i + 1, s] if i < head else 0.0  # the head's last body: slot head + 1 is the kicks'
                vn = v[i, s] + hb * (f[i, s] - below) * invm[i, s]
                v[i, s] = vn if active[s] != 0.0 else v[i, s]
        for i in range(head + 1):
            for s in range(W):
                un = u[i, s] + ha * v[i, s]
                u[i, s] = un if active[s] != 0.0 else u[i, s]
        for i in range(1, head + 1):
            for s in range(W):
                d = d0[i, s] + u[i - 1, s] - u[i, s]
                flip = (d > 0.0) != (closed[i - 1, s] != 0.0)
                changed[s] = 1.0 if flip and active[s] != 0.0 else changed[s]
                d = d if d > 0.0 else 0.0
                fn = A[i, s] * d * math.sqrt(d) - load[i, s]
                f[i, s] = fn if active[s] != 0.0 else f[i, s]


@jit
def _attempt(u, v, invm, f, A, d0, load, head, a_coef, b_coef, k, pending, active, changed, closed, saved):
    """A substep of k seconds on the active shots (_lane_substep). A shot in which a head
    contact changed state is put back as it was before it (its pending kick kept) and keeps
    changed[s] = 1; every other active shot owes the substep's closing kick (pending[s]).
    Returns whether any shot changed. saved: (3, head + 1, shots)."""
    W = u.shape[1]
    for i in range(head + 1):
        for s in range(W):
            saved[0, i, s] = u[i, s]
            saved[1, i, s] = v[i, s]
            saved[2, i, s] = f[i, s]
    _lane_substep(u, v, invm, f, A, d0, load, head, a_coef, b_coef, k, pending, active, changed, closed)
    owed = b_coef[a_coef.shape[0]] * k
    hits = 0.0
    for s in range(W):
        hit = active[s] != 0.0 and changed[s] != 0.0
        changed[s] = 1.0 if hit else 0.0
        pending[s] = pending[s] if hit or active[s] == 0.0 else owed
        hits += changed[s]
    if hits == 0.0:
        return False
    for i in range(head + 1):
        for s in range(W):
            back = changed[s] != 0.0
            u[i, s] = saved[0, i, s] if back else u[i, s]
            v[i, s] = saved[1, i, s] if back else v[i, s]
            f[i, s] = saved[2, i, s] if back else f[i, s]
    return True


@jit(inline="always")
def _resolved_substeps(u, v, invm, f, A, d0, load, head, a_coef, b_coef, k, n, saved, lanes):
    """n substeps of k seconds on the head of every busy shot (lanes[0] != 0), each substep
    across a change of contact state taken again as REFINE, and the piece across it as
    REFINE again; ends with the owed closing kick applied. All shots of a level run at
    once, masked (the shots of a batch strike at about the same substeps); each shot gets
    the operations of its own sequence of substeps. saved: (2, 3, head + 1, shots);
    lanes: (5 + head, shots) work array (busy, pending, changed, the shots refined at
    each level, the head contacts' states)."""
    busy, pending, changed, fine, finest, closed = lanes[0], lanes[1], lanes[2], lanes[3], lanes[4], lanes[5:]
    last = b_coef[a_coef.shape[0]]
    W = u.shape[1]
    for s in range(W):
        pending[s] = 0.0
    for _ in range(n):
        if not _attempt(u, v, invm, f, A, d0, load, head, a_coef, b_coef, k, pending, busy, changed, closed,
                        saved[0]):
            continue
        for s in range(W):  # element by element: numba's array slice assignment compiles its error message
            fine[s] = changed[s]
        for _ in range(REFINE):
            if not _attempt(u, v, invm, f, A, d0, load, head, a_coef, b_coef, k / REFINE, pending, fine, changed,
                            closed, saved[1]):
                continue
            for s in range(W):
                finest[s] = changed[s]
            kk = k / REFINE / REFINE
            for _ in range(REFINE):
                _lane_substep(u, v, invm, f, A, d0, load, head, a_coef, b_coef, kk, pending, finest, changed, closed)
                for s in range(W):
                    pending[s] = last * kk if finest[s] != 0.0 else pending[s]
    for i in range(head + 1):
        for s in range(W):
            below = f[i + 1, s] if i < head else 0.0
            vn = v[i, s] + pending[s] * (f[i, s] - below) * invm[i, s]
            v[i, s] = vn if busy[s] != 0.0 else v[i, s]


@jit
def head_flow(u, v, invm, f, A, d0, load, head, a_coef, b_coef, h, n, work, lanes):
    """Advance every shot's head by h seconds (u, v, f in place): n resolved substeps where
    a head contact is or may come closed; elsewhere the exact flow under the constant
    loads, u += h v + h^2 a / 2, v += h a (the forces stay -load), branch-free over the
    shots. work: (2, 3, head + 1, shots) saved states; lanes: (5 + head, shots) float64
    (_resolved_substeps)."""
    busy = lanes[0]
    _busy(u, v, invm, d0, load, head, a_coef, b_coef, h, busy)
    resolved = False
    for s in range(busy.shape[0]):
        resolved = resolved or busy[s] != 0.0
    if resolved:
        _resolved_substeps(u, v, invm, f, A, d0, load, head, a_coef, b_coef, h / n, n, work, lanes)
    for i in range(head + 1):
        for s in range(u.shape[1]):
            below = f[i + 1, s] if i < head else 0.0
            acc = (f[i, s] - below) * invm[i, s]
            free = 1.0 - busy[s]
            u[i, s] += free * (h * v[i, s] + 0.5 * h * h * acc)
            v[i, s] += free * (h * acc)


@jit(inline="always")
def slow_net(f, j, head, s):
    """Net force on body j from the slots the method's kicks carry (all but the head's)."""
    if head == 0:
        return f[j, s] - f[j + 1, s]
    above = f[j, s] if j > head else 0.0
    below = f[j + 1, s] if j + 1 > head else 0.0
    return above - below
