"""The passes of the batched kernel over one chunk's rows (numba): arrays (bodies, shots),
the shots innermost, each row's loop over the shots vectorised (ensemble.py runs them).
Every shot performs the single-shot kernel's operations (step.py, forces.py) in the same
order, so the same bits.

The per-row helpers are inlined (numba's inline="always"): LLVM does not inline numba's
calls, and a call per row cost as much as the row of 64 shots itself
(tests/solver/test_vectorised.py guards this).
"""
import math

from numerics.jit import jit
from rig.model.contact import PLASTIC, POWER
from rig.model.laws.thornton import AP, DC, DS, SPAN_END, SPAN_FIRST, plastic_force
from rig.solver.kernels.forces import open_span, power
from rig.solver.kernels.multirate import head_flow


@jit(inline="always")
def contact_row(u, A, d0, load, f, i):
    """Dynamic Hertz force of contact slot i for every shot: A d^(3/2) - load
    (forces.hertz_forces)."""
    for s in range(u.shape[1]):
        d = d0[i, s] + u[i - 1, s] - u[i, s]
        d = d if d > 0.0 else 0.0
        f[i, s] = A[i, s] * d * math.sqrt(d) - load[i, s]


@jit(inline="always")
def power_row(u, A, d0, load, f, i, expo):
    """Contact slot i of every shot whose exponent is not 3/2 by its own law, A d^n - load,
    after contact_row (forces.other_law's operations)."""
    for s in range(u.shape[1]):
        n = expo[i, s]
        if n != 1.5:
            d = d0[i, s] + u[i - 1, s] - u[i, s]
            f[i, s] = A[i, s] * power(d if d > 0.0 else 0.0, n) - load[i, s]


@jit
def other_laws(u, A, d0, load, f, con, state, law, lo, hi):
    """POWER: slots lo.. whose exponent is not 3/2 renewed by their own law; PLASTIC: the
    slots of each shot's span past their elastic limit or of another exponent, by the
    elastic-plastic law of their memory ``state`` (forces.plastic_fixup's operations); after
    a pass renewed every slot as Hertz's (PLASTIC: each slot's elastic curve) from the same
    positions (no pass
    reads a slot's force after renewing it, so this is the same as renewing them in the
    pass). Apart from the pass: inlined in its loop, this branch kept numba's atomic
    reference counts there (6% of the pass)."""
    if law == POWER:
        for i in range(max(lo, 1), hi):
            power_row(u, A, d0, load, f, i, con[0])
    elif law == PLASTIC:  # after a pass over the elastic curves: the slots it does not give, in each span
        first, end = hi, 0
        for s in range(u.shape[1]):
            first = min(first, int(state[SPAN_FIRST, 0, s]))
            end = max(end, int(state[SPAN_END, 0, s]))
        for i in range(max(lo, 1, first), min(hi, end)):
            for s in range(u.shape[1]):
                d = d0[i, s] + u[i - 1, s] - u[i, s]
                inside = state[SPAN_FIRST, 0, s] <= i < state[SPAN_END, 0, s]
                if inside and (d > state[DC, i, s] or con[0, i, s] != 1.5):
                    f[i, s] = plastic_force(d, A[i, s], con[0, i, s], state, i, s) - load[i, s]


@jit
def shot_forces(u, A, d0, load, f, law, con, state):
    A_el, d0_el = (state[AP], state[DS]) if law == PLASTIC else (A, d0)
    if law == PLASTIC:
        open_span(state)  # every slot looked at until a step's end finds the near ones
    for i in range(1, u.shape[0]):
        contact_row(u, A_el, d0_el, load, f, i)
    other_laws(u, A, d0, load, f, con, state, law, 1, u.shape[0])


@jit
def head_kick(v, invm, f, hb, head):
    """The method's kick of the head's last body (slot head + 1 only)."""
    for s in range(v.shape[1]):
        v[head, s] += hb * (0.0 - f[head + 1, s]) * invm[head, s]


@jit(inline="always")
def kick_drift_row(u, v, invm, f, hb, ha, i):
    """Kick then drift body i of every shot."""
    for s in range(u.shape[1]):
        vi = v[i, s] + hb * (f[i, s] - f[i + 1, s]) * invm[i, s]
        v[i, s] = vi
        u[i, s] += ha * vi


@jit
def kick_drift(u, v, invm, f, hb, ha, head, reach):
    start = 0
    if head > 0:
        head_kick(v, invm, f, hb, head)
        start = head + 1
    for i in range(start, reach):
        kick_drift_row(u, v, invm, f, hb, ha, i)


@jit
def kick_drift_forces(u, v, invm, f, A, d0, load, hb, ha, head, multirate, a_coef, b_coef, n_sub, h_work, h_busy,
                       law, con, state, reach):
    """kick_drift (and the head's flow) then shot_forces in one pass over rows 0..reach-1 (the
    others at rest bit for bit, integrators.integrate's front): row i is kicked and drifted
    (reading f[i], f[i+1], not yet renewed), then contact i is renewed from rows i-1 and i
    (both moved). The same operations as the two passes, so the same bits."""
    start = 0
    if multirate:  # a Constant (bundles.Method): 1 where head > 0; without, no head flow compiled
        head_kick(v, invm, f, hb, head)
        head_flow(u, v, invm, f, A, d0, load, head, a_coef, b_coef, ha, n_sub, h_work, h_busy)
        start = head + 1
    A_el, d0_el = (state[AP], state[DS]) if law == PLASTIC else (A, d0)  # PLASTIC: each slot's elastic curve
    for i in range(start, reach):
        kick_drift_row(u, v, invm, f, hb, ha, i)
        if i >= 1:
            contact_row(u, A_el, d0_el, load, f, i)
    other_laws(u, A, d0, load, f, con, state, law, start, reach)
