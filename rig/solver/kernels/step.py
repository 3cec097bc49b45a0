"""One step of the splitting composition (numba): kick(b_0) drift(a_0) ... drift(a_{S-1}),
its closing kick b_S owed to the next step (integrators.py).

Each stage's kick, drift and renewal of the contact forces run fused in one pass over the
bodies (``fused_run``), and the chain is swept in blocks that stay in cache (``step``).
With a multirate head (head > 0, see rig/solver/stepsize.py) the kicks carry every contact but
the first ``head`` ones, and each drift moves bodies 0..head by multirate.head_flow
(``sub[s]`` substeps of the same method in drift s) instead of a plain drift. The
scheduled force of the ring magnet is a kick of its own (``external_kick``).
"""
import math

import numpy as np

from numerics.jit import jit
from rig.model.contact import PLASTIC, POWER
from rig.solver.kernels.forces import other_law, plastic_fixup
from rig.solver.kernels.layout import LINE
from rig.solver.kernels.multirate import head_flow


@jit
def schedule_force(t, times, forces):
    """Piecewise-linear force (N) at time t from a table; held constant outside it."""
    n = times.shape[0]
    if t <= times[0]:
        return forces[0]
    if t >= times[n - 1]:
        return forces[n - 1]
    lo = 0
    hi = n - 1
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if times[mid] <= t:
            lo = mid
        else:
            hi = mid
    w = (t - times[lo]) / (times[hi] - times[lo])
    return forces[lo] + w * (forces[hi] - forces[lo])


@jit(inline="always")
def external_kick(v, invm, h, t, sched_body, sched_t, sched_f):
    """Kick by the scheduled force at time t; returns its impulse (N s)."""
    if sched_t.shape[0] == 0:
        return 0.0
    fe = schedule_force(t, sched_t, sched_f)
    v[sched_body] += h * fe * invm[sched_body]
    return h * fe


@jit(inline="always")
def fused_run(u, v, invm, f, A, d0, load, hb, ha, lo, hi, law, expo):
    """Bodies lo..hi-1 (lo >= 1), in order: kick v += hb (f_above - f_below)/m, drift
    u += ha v, then renew contact slot i's elastic force from bodies i-1 and i (both moved;
    forces.elastic_forces' operations). Slot i + 1 is still the old force when body i is
    kicked, so one pass does what a kick-drift pass and a force pass do. ``law``: POWER
    renews the slots whose exponent ``expo`` is not 3/2 again by their own law
    (forces.other_law; no slot's force is read in the pass that renews it, so this is the
    same as renewing them in the pass), any other code is Hertz's. PLASTIC's caller passes
    each slot's elastic curve (its memory's A_p and d0 - delta_p) for A and d0, and renews
    after it the slots the curve does not give (step, forces.plastic_fixup).

    The index is unsigned: with a signed start known only at run time numba keeps its
    negative-index wraparound in the loop and LLVM no longer vectorises it
    (tests/solver/test_vectorised.py guards this). The bodies up to the first multiple of
    LINE run first: the vector loop then starts on a cache line of arrays placed by
    layout.py (one call for both parts: each call of an inlined function costs atomic
    reference counts of its arrays)."""
    one = np.uint64(1)
    u_prev = u[lo - 1]
    line = min(hi, (lo + LINE - 1) // LINE * LINE)
    for part in range(2):  # bodies up to the first cache line, then the rest from it (aligned, layout.py)
        start, stop = (lo, line) if part == 0 else (line, hi)
        for i in range(np.uint64(start), np.uint64(stop)):
            vi = v[i] + hb * (f[i] - f[i + one]) * invm[i]
            v[i] = vi
            ui = u[i] + ha * vi
            u[i] = ui
            d = d0[i] + u_prev - ui
            d = d if d > 0.0 else 0.0
            f[i] = A[i] * d * math.sqrt(d) - load[i]
            u_prev = ui
    if law == POWER:  # not in the loop: a pow there (even behind a branch) stops it vectorising
        other_law(u, A, d0, load, f, expo, lo, hi)


@jit
def closing_kick(v, invm, f, hb, head, reach):
    """Kick only (the owed closing kick), bodies 0..reach-1 (the others are at rest and
    unforced, see ``step``); the head's bodies get only the force of slot head + 1 (their
    own contacts are the head flow's)."""
    start = 0
    if head > 0:
        v[head] += hb * (0.0 - f[head + 1]) * invm[head]
        start = head + 1
    for i in range(np.uint64(start), np.uint64(reach)):
        v[i] = v[i] + hb * (f[i] - f[i + np.uint64(1)]) * invm[i]


BLOCK = 2048  # bodies per block of a step's wavefront (their arrays stay in the core's L2 cache)


@jit(inline="always")
def step(u, v, invm, f, A, d0, load, law, expo, state, A_el, d0_el, a_coef, b_coef, dt, t, pending, head, sub,
          multirate, sched_body, sched_t, sched_f, wall_slot, heads, h_work, h_busy, impulses, reach):
    """One step of the composition (its closing kick owed), bodies 0..reach-1, every stage.
    ``reach``: the bodies beyond it are still at rest and unforced (integrators.rest_from):
    the step would leave them bit for bit as they are.

    Stage s on body i needs slot i + 1 at stage s - 1 and leaves slot i at stage s, so
    stage s may run one body behind stage s - 1: the chain is swept in blocks of BLOCK
    bodies, each block taken through every stage (stage s on bodies kB - s .. (k+1)B - s)
    while it is in cache, instead of every stage streaming the whole chain from memory.
    Each body sees the same operations in the same order as in stage-by-stage sweeps.
    With a multirate head (``multirate`` 1: head > 0), bodies 0..head get the kick of slot
    head + 1 and the head's flow (multirate.head_flow) instead. ``heads``: the
    (bodies, 1) views the head flow takes, h_work and h_busy its work arrays;
    impulses[0] += the wall's dynamic impulse, impulses[1] += the schedule's (N s).
    """
    nb = reach
    u2, v2, im2, f2, A2, d02, load2 = heads
    n_blocks = max(1, (nb + BLOCK - 1) // BLOCK)
    for k in range(n_blocks):
        ts = t
        for s in range(a_coef.shape[0]):
            hb = b_coef[s] * dt
            if s == 0:
                hb += pending
            h = a_coef[s] * dt
            lo = max(k * BLOCK - s, 0)
            hi = nb if k == n_blocks - 1 else (k + 1) * BLOCK - s
            if k == n_blocks - 1 and wall_slot > 0:
                impulses[0] += hb * f[wall_slot]
            if k == 0:
                if sched_t.shape[0] > 0:  # entered only with a schedule: the inlined kick's reference counts
                    impulses[1] += external_kick(v, invm, hb, ts, sched_body, sched_t, sched_f)
                if multirate:  # a Constant (bundles.Method): a solve without a head compiles no head flow
                    v[head] += hb * (0.0 - f[head + 1]) * invm[head]
                    head_flow(u2, v2, im2, f2, A2, d02, load2, head, a_coef, b_coef, h, sub[s], h_work, h_busy)
                    lo = head + 1
                else:
                    v0 = v[0] + hb * (f[0] - f[1]) * invm[0]
                    v[0] = v0
                    u[0] += h * v0
                    lo = 1
            if hi > lo:
                fused_run(u, v, invm, f, A_el, d0_el, load, hb, h, lo, hi, law, expo)
                if law == PLASTIC:  # the slots past their elastic limit, apart: no call in the pass
                    plastic_fixup(u, A, d0, load, f, expo, state, lo, hi)
            ts += h
