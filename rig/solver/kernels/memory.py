"""Renewing the contacts' memory at a step's end (numba; rig.model.laws.thornton.commit):
arrays (bodies, shots), the single-shot kernel's as (bodies, 1) views, so that both kernels
renew the same bits."""
from instruments.jit import jit
from rig.model.laws.thornton import commit
from rig.solver.kernels.record import synced_velocity


@jit
def plastic_commit(u, v, invm, f, A, d0, con, state, pending, head, sched_body, f_sched, dt, hi):
    """Renew the memory of slots 1..hi-1 of every shot at a step's end, dt (s) after the
    last: each slot's overlap and its closing rate, the velocities synchronised as
    record.probe_overlaps does (the owed closing kick of ``pending`` s, the schedule's force
    f_sched (N) on sched_body, -1: none)."""
    for i in range(1, hi):
        for s in range(u.shape[1]):
            rate = (synced_velocity(i - 1, s, v, invm, f, pending, head, sched_body, f_sched)
                    - synced_velocity(i, s, v, invm, f, pending, head, sched_body, f_sched))
            commit(d0[i, s] + u[i - 1, s] - u[i, s], rate, dt, A[i, s], con[0, i, s], con[4, i, s], con[5, i, s],
                   state, i, s)
