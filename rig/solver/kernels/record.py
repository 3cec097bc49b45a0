"""What a solve records between step ends (numba), shared by the single-shot and batched
kernels so that both record the same bits: arrays are (bodies, shots), the single-shot
kernel passes (bodies, 1) views.

A channel is a weighted sum of contact forces. At each step end the overlap d (m) of
every contact a channel reads and its rate d' (m/s) are kept; at an output instant inside
the step each overlap is interpolated by the cubic Hermite polynomial through those two
ends, and the contact law is applied to it. The overlap is smooth in time even where a
contact closes or opens, so the recorded force keeps the integrator's accuracy there;
interpolating the force itself would be accurate only to O(h^1.5) in such a step (the
force grows as (t - t0)^(3/2) from the instant t0 the contact closes). A contact with
memory (PLASTIC) is recorded by the law its memory gives through the step, before the
step's end renews it.
"""

from numerics.jit import jit
from rig.model.contact import PLASTIC
from rig.solver.kernels.forces import contact_force, plastic_contact
from rig.solver.kernels.multirate import slow_net


@jit(inline="always")
def synced_velocity(j, s, v, invm, f, pending, head, sched_body, f_sched):
    """Velocity (m/s) of body j of shot s once the owed closing kick of ``pending`` seconds
    is applied (the scheduled force f_sched (N) on sched_body included; -1: none)."""
    im = invm[j, s]  # read outside the branch: numba keeps reference counts of arrays read in a
    # branch of an inlined function, and those atomic operations cost 40x the loop's arithmetic
    vj = v[j, s] + pending * slow_net(f, j, head, s) * im
    if j == sched_body:
        vj += pending * f_sched * im
    return vj


@jit
def probe_overlaps(u, v, invm, f, d0, ch_slot, ch_weight, pending, head, sched_body, f_sched, d, r):
    """d[c, k, s], r[c, k, s]: overlap (m) and its rate (m/s) of contact k of channel c of
    every shot s, at a step end."""
    for c in range(ch_slot.shape[0]):
        for k in range(ch_slot.shape[1]):
            if ch_weight[c, k] != 0.0:
                i = ch_slot[c, k]
                for s in range(u.shape[1]):
                    d[c, k, s] = d0[i, s] + u[i - 1, s] - u[i, s]
                    r[c, k, s] = (synced_velocity(i - 1, s, v, invm, f, pending, head, sched_body, f_sched)
                                  - synced_velocity(i, s, v, invm, f, pending, head, sched_body, f_sched))


@jit
def hermite_weights(x, h, w, k):
    """Column k of w (4, n) gets the weights of the cubic Hermite interpolant at fraction x
    of a step of h seconds: y(x) = w0 y0 + w1 r0 + w2 y1 + w3 r1 (values y, rates r at the
    step's ends)."""
    x2 = x * x
    x3 = x2 * x
    w[0, k] = 2.0 * x3 - 3.0 * x2 + 1.0
    w[1, k] = (x3 - 2.0 * x2 + x) * h
    w[2, k] = 3.0 * x2 - 2.0 * x3
    w[3, k] = (x3 - x2) * h


@jit
def hermite(w, k, y0, r0, y1, r1):
    """The interpolant with the weights of column k (hermite_weights)."""
    return w[0, k] * y0 + w[1, k] * r0 + w[2, k] * y1 + w[3, k] * r1


@jit
def recorded_force(w, col, x, c, s, ch_slot, ch_weight, A, con, law, state, d_old, r_old, d_new, r_new):
    """Channel c's force (N) in shot s at fraction x of a step, whose Hermite weights are
    column col of w: sum over its contacts of weight x the contact law (forces.contact_force;
    con: (4, bodies, shots) exponents, damping times, dashpots and their exponents) at the
    interpolated overlap d and the rate d' linear in the step (which only a law with
    viscous terms reads; ``state``: the contacts' memory, PLASTIC)."""
    y = 0.0
    for k in range(ch_slot.shape[1]):
        wk = ch_weight[c, k]
        if wk != 0.0:
            i = ch_slot[c, k]
            d = hermite(w, col, d_old[c, k, s], r_old[c, k, s], d_new[c, k, s], r_new[c, k, s])
            rate = (1.0 - x) * r_old[c, k, s] + x * r_new[c, k, s]
            if law == PLASTIC:
                fk, _ = plastic_contact(d, rate, A[i, s], con[0, i, s], con[2, i, s], state, i, s)
            else:
                fk, _ = contact_force(d, rate, A[i, s], con[0, i, s], con[1, i, s], con[2, i, s], con[3, i, s], law)
            y += wk * fk
    return y
