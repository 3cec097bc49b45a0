"""A chain at rest bit for bit: the slot loads and static overlaps rounded so that every
body meant to rest has forces that cancel exactly as the kernels compute them
(rig.solver.problem.problem_arrays calls it before the arrays that read d0)."""
from __future__ import annotations

REST_TOLERANCE = 1e-12  # a body's net force at rest below this x its loads is rounding, not physics
NUDGES = 6  # ulps either side tried by balance_at_rest, of a slot's static overlap and of its load
INTERPRETED_BODIES = 2000  # a single shot's chain up to this many bodies is balanced by the interpreter (about
# 1 ms a thousand bodies), not the compiled kernel (0.7 s of compile on a cold cache)


def balance_at_rest(load, A, d0, expo, invm):
    """Round the slot loads (N, (shots, bodies + 1)) and static overlaps (m, (shots,
    bodies)) so that every body meant to rest is at rest bit for bit: its two slots' forces
    at rest, elastic(d0) - load, computed as the kernels compute them, are the same number,
    and its kick is exactly 0.

    A body is meant to rest where those two forces differ by rounding only (by less than
    REST_TOLERANCE x its loads); the lower slot's d0 and load then move by at most NUDGES
    ulps each, to the nearest pair for which the kernels' subtraction gives the upper
    slot's force exactly (left as they were where none does). Beads below a striker in
    flight rest too: every slot's load carries its weight, which the slot of its gap
    carries rounded to a multiple of the ulp of the largest load (a part in 1e13 at most
    for chains under 1e4 beads), so that the slots below can carry it exactly. The change
    is otherwise a few parts in 1e16; the kernels integrate the bodies ahead of a pulse
    only where they are at rest bit for bit (rig/solver/kernels/integrators.py)."""
    from rig.solver.kernels.forces import balance_at_rest as balance  # numba: loaded when a problem is built

    if A.shape[0] == 1 and A.shape[1] <= INTERPRETED_BODIES:  # one short chain: no compile (the same bits)
        from numerics.jit import interpreted

        interpreted(balance)(0, 1, load, A, d0, expo, invm, REST_TOLERANCE, NUDGES)
        return
    from numerics.threads import over_threads

    over_threads(A.shape[0], balance, load, A, d0, expo, invm, REST_TOLERANCE, NUDGES)
