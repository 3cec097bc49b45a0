"""Renewing the contacts' memory at a step's end (numba; rig.model.laws.thornton.commit):
arrays (bodies, shots), the single-shot kernel's as (bodies, 1) views, so that both kernels
renew the same bits.

Most contacts are far from their elastic limit at most step ends: for those a step's end
only keeps the overlap and its mean rate over the step (thornton's DLAST, RLAST), three
loads and two stores. A contact near its limit (its overlap within NEAR of its last step's
changes of it), or one whose yield rises with the rate (m > 0) closing faster than it has,
gets thornton.commit, with its closing rate from the synchronised velocities.

The near contacts are also the only ones that can pass their elastic limit in the next
step: their span, first to last, is kept in slot 0's memory (thornton.SPAN_FIRST,
SPAN_END; slot 0 joins no bodies) and the force passes check only those slots for the
envelope (forces.plastic_fixup), instead of every slot at every stage. Where any exponent
is not 3/2 every slot is renewed by the law at every stage (``every``)."""
from numerics.jit import jit
from rig.model.laws.thornton import DC, DLAST, RLAST, RMAX, SPAN_END, SPAN_FIRST, WORK, commit
from rig.solver.kernels.record import synced_velocity

NEAR = 3.0  # a contact is near its elastic limit within this many of its last step's changes of overlap


@jit
def plastic_commit(u, v, invm, f, A, d0, con, state, pending, head, sched_body, f_sched, dt, hi, every):
    """Renew the memory of slots 1..hi-1 of every shot at a step's end, dt (s) after the
    last, and each shot's span of near slots (module doc; the velocities synchronised as
    record.probe_overlaps does: the owed closing kick of ``pending`` s, the schedule's force
    f_sched (N) on sched_body, -1: none). every: the span is every slot."""
    W = u.shape[1]
    for s in range(W):
        state[SPAN_FIRST, 0, s] = hi
        state[SPAN_END, 0, s] = 0.0
    for i in range(1, hi):
        for s in range(W):
            d = d0[i, s] + u[i - 1, s] - u[i, s]
            change = d - state[DLAST, i, s]
            near = max(d, state[DLAST, i, s]) + NEAR * abs(change) > state[DC, i, s]
            faster = con[4, i, s] != 0.0 and change > state[RMAX, i, s] * dt
            if near or faster:
                rate = (synced_velocity(i - 1, s, v, invm, f, pending, head, sched_body, f_sched)
                        - synced_velocity(i, s, v, invm, f, pending, head, sched_body, f_sched))
                commit(d, rate, dt, A[i, s], d0[i, s], con[0, i, s], con[4, i, s], con[5, i, s], state, i, s)
            else:
                state[DLAST, i, s] = d
                state[RLAST, i, s] = change / dt
            if near:
                state[SPAN_FIRST, 0, s] = min(state[SPAN_FIRST, 0, s], i)
                state[SPAN_END, 0, s] = i + 1.0
    if every:
        for s in range(W):
            state[SPAN_FIRST, 0, s] = 1.0
            state[SPAN_END, 0, s] = state.shape[1]


@jit
def other_exponent(A, con) -> bool:
    """Whether a contact of any shot has an exponent other than 3/2 (A (bodies, shots), con
    (rows, bodies, shots)): plastic_commit's ``every``."""
    for i in range(A.shape[0]):
        for s in range(A.shape[1]):
            if A[i, s] > 0.0 and con[0, i, s] != 1.5:
                return True
    return False


@jit
def plastic_work(state, s) -> float:
    """The plastic work (J) the contacts of shot s took, which the energy carries: dissipated."""
    w = 0.0
    for i in range(state.shape[1]):
        w += state[WORK, i, s]
    return w
