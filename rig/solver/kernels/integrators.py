"""Fixed-step symplectic splitting integrators for the chain (numba).

One kernel runs every method of the registry: a symmetric composition of kicks
(v += b_s dt a(u)) and drifts (u += a_s dt v),

    kick(b_0) drift(a_0) kick(b_1) drift(a_1) ... drift(a_{S-1}) kick(b_S),

with the forces of the last stage reused as the first of the next step (FSAL), so one
step costs S force evaluations; the closing kick b_S is merged into the next step's first
kick, and velocities are synchronised only where needed (probe bodies every step; every
body at checks, frames and the end). Velocity Verlet is a = [1], b = [1/2, 1/2].

Recorded channels are linear combinations of contact forces, interpolated onto a uniform
output grid by cubic Hermite interpolation between step ends (force and its rate
dF/dt = (3/2) A d^(1/2) d(d)/dt), so the output grid may be finer than the step.

One step of the composition is step.py's (its fused kick-drift-force passes, the blocks
of its wavefront, the multirate head); this module drives the steps: the records, the
checks, the frames and the dissipation.

The front. Beads that the pulse has not reached are at rest, their contact forces equal
and constant: a step leaves them bit for bit as they are. A stage moves at most one more
body than the last (body i is pushed by slots i and i + 1, slot i + 1 renewed from bodies
i and i + 1), so with bodies ``still`` onwards untouched before a step, the step and its
closing kick change none beyond still + S (S stages). Each step integrates bodies
0..still + S + 1 only and finds ``still`` again among the bodies it took: the same bits as
integrating every body, at the cost of the part of the chain in motion. (Not with
dissipation, whose flows take every body.)

Dissipation. The force passes carry the contacts' elastic part only; the contacts'
viscous terms and the holder's drag and friction are a flow of the velocities, taken
apart in a Strang splitting E(dt/2) S(dt) E(dt/2) (dissipation.py): second order where
they act, each step then ending synchronised. E counts the energy it takes, so the
balance E(t) + dissipated = E(0) closes to the method's own error.
"""

import numpy as np

from numerics.jit import jit
from rig.model.contact import PLASTIC
from rig.model.laws.thornton import AP, DS
from rig.solver.kernels.dissipation import dissipate, holder_factors
from rig.solver.kernels.forces import elastic_forces, state_sums
from rig.solver.kernels.memory import other_exponent, plastic_commit, plastic_work
from rig.solver.kernels.record import hermite, hermite_weights, probe_overlaps, recorded_force
from rig.solver.kernels.report import (
    BODIES_STEPPED,
    DISSIPATED,
    END_TIME,
    ENERGY_ERROR,
    MOMENTUM_ERROR,
    STATUS,
    STEPS,
    WALL_IMPULSE,
)
from rig.solver.kernels.step import closing_kick, external_kick, schedule_force, step


@jit
def rest_from(v, invm, f, first):
    """The first body r >= ``first`` from which every body is at rest (v = 0) with forces
    that cancel bit for bit (f[i] = f[i + 1], or immovable): a kick leaves such a body as it
    is, and a drift too. nb where no movable body is so (the wall's body alone is no front)."""
    nb = v.shape[0]
    r = nb
    while r > first and v[r - 1] == 0.0 and (f[r - 1] == f[r] or invm[r - 1] == 0.0):
        r -= 1
    for i in range(r, nb):
        if invm[i] != 0.0:
            return r
    return nb


@jit(inline="always")
def still_from(u, v, u_rest, lo, hi):
    """The first body r in [lo, hi] from which bodies r..hi-1 of every shot are where they
    rest (u = u_rest) with v = 0; arrays (bodies, shots), a single shot's as (bodies, 1)."""
    r = hi
    while r > lo:
        for s in range(u.shape[1]):
            if v[r - 1, s] != 0.0 or u[r - 1, s] != u_rest[r - 1, s]:
                return r
        r -= 1
    return r


@jit
def integrate(u, v, f, chain, contacts, holder, method, schedule, record, checks, diag, front):
    """Integrate method.n_steps of size method.dt in place; fill record.out (n_ch, n_out)
    and record.frames (n_fr, nb); the bundles are bundles.py's (their fields, units).

    u, v (size nb): displacements (m) and velocities (m/s), renewed in place; f (size
    nb + 1): the contact forces' work array (layout.working_arrays places it with u, v and
    the chain's invm, A, d0 and load, which the passes read). contacts.state is renewed in
    place (PLASTIC only).
    diag (float64[report.DIAGNOSTICS]) receives, at report.py's slots: max relative energy
    error, max relative momentum balance error, total wall impulse (N s), status (0 ok,
    1 unstable), steps done, final time, dissipated energy (J), bodies integrated summed
    over the steps.
    Energy: E = kinetic + elastic - work of constant loads - work of the scheduled force,
    and E + dissipated stays E(0).
    Momentum balance: P(t) - P(0) - [t * sum(constant loads) + J_schedule - J_wall + J_holder].
    chain.load[i] (size nb + 1): constant force carried from above through slot i (N).
    front: integrate only the bodies the pulse has reached (module doc); False: every body
    every step (the same bits).
    """
    mass, invm, bias, load, A, d0, d_limit = chain  # each bundle's fields, in their order (bundles.py)
    law, con, state = contacts
    onsite, slip, viscous_rate, flows = holder
    a_coef, b_coef, dt, n_steps, head, sub, multirate = method
    sched_body, sched_t, sched_f = schedule.body, schedule.t, schedule.f
    ch_slot, ch_weight, sample_dt, out = record.ch_slot, record.ch_weight, record.sample_dt, record.out
    frame_dt, frames = record.frame_dt, record.frames
    check_every, e_ref, p_ref, wall_slot = checks.check_every, checks.e_ref, checks.p_ref, checks.wall_slot
    nb = u.shape[0]
    f[:] = 0.0
    f[nb] = -load[nb]
    n_drift = a_coef.shape[0]
    n_ch = ch_slot.shape[0]
    n_out = out.shape[1]
    n_frames = frames.shape[0]
    has_sched = sched_t.shape[0] > 0
    viscous = False
    holder = False
    for i in range(nb):
        viscous = viscous or con[1, i] != 0.0 or con[2, i] != 0.0
        holder = holder or onsite[0, i] != 0.0 or onsite[1, i] != 0.0
    dissipative = flows  # a constant (bundles.Holder): a chain without flows compiles no dissipation

    state3 = state.reshape((state.shape[0], nb, 1))
    expo = con[0]
    A_el, d0_el = (state[AP], state[DS]) if law == PLASTIC else (A, d0)  # the force passes' elastic curves
    every = other_exponent(A.reshape((nb, 1)), con.reshape((con.shape[0], nb, 1)))  # PLASTIC: every slot renewed
    elastic_forces(u, A, d0, load, f, law, con, state3)
    # (bodies, 1) views for the multirate head, the records and the dissipation (shared with the batched kernel)
    heads = (u.reshape((nb, 1)), v.reshape((nb, 1)), invm.reshape((nb, 1)), f.reshape((nb + 1, 1)),
             A.reshape((nb, 1)), d0.reshape((nb, 1)), load.reshape((nb + 1, 1)))
    con3 = con.reshape((con.shape[0], nb, 1))
    hold = holder_factors(onsite.reshape((2, nb, 1)), 0.5 * dt, viscous)  # E(dt/2)'s holder flows
    work = np.zeros((5, nb + 1, 1))  # the dissipation's work arrays
    lost = np.zeros(1)  # the energy dissipation took (J), its impulse on the wall and the holder's (N s)
    j_visc = np.zeros(1)
    j_holder = np.zeros(1)
    h_work, h_busy = np.empty((2, 3, head + 1, 1)), np.empty((5 + head, 1))  # the head flow's work arrays
    # sum of constant loads, less the part the wall's slot carries (j_wall is dynamic)
    wall_load = load[wall_slot] if wall_slot > 0 else 0.0
    net_const = load[nb] - wall_load
    sums = np.empty(3)  # energy (J), momentum (kg m/s), largest d / d_limit of one state
    m2, b2, dl2 = mass.reshape((nb, 1)), bias.reshape((nb, 1)), d_limit.reshape((nb, 1))
    state_sums(heads[0], heads[1], m2, b2, heads[4], con3[0], heads[5], dl2, law, state3, sums[0:1], sums[1:2],
               sums[2:3])
    e0, p0 = sums[0], sums[1]
    impulses = np.zeros(2)  # the wall's dynamic impulse, the schedule's (N s)
    w_sched = 0.0

    u2, v2, im2, f2, A2, d02, load2 = heads
    u_rest = u2.copy()
    first = max(head + 1, sched_body + 1 if has_sched else 1)
    still = rest_from(v, invm, f, first) if front and not dissipative else nb
    d_old = np.zeros((n_ch, ch_slot.shape[1], 1))  # overlaps (m) and rates (m/s) the channels read
    r_old = np.zeros_like(d_old)
    d_new = np.zeros_like(d_old)
    r_new = np.zeros_like(d_old)
    w = np.empty((4, 1))
    probe_overlaps(u2, v2, im2, f2, d02, ch_slot, ch_weight, 0.0, head, sched_body, 0.0, d_old, r_old)
    if n_out > 0:
        hermite_weights(0.0, dt, w, 0)
        for c in range(n_ch):
            out[c, 0] = recorded_force(w, 0, 0.0, c, 0, ch_slot, ch_weight, A2, con3, law, state3, d_old, r_old,
                                       d_old, r_old)
    j_out = 1
    u_old = np.empty(nb if n_frames > 0 else 0)
    v_old = np.empty(nb if n_frames > 0 else 0)
    if n_frames > 0:
        for i in range(nb):  # element by element: numba's array slice assignment compiles its error message
            frames[0, i] = u[i]
    j_frame = 1

    e_err = 0.0
    p_err = 0.0
    status = 0
    steps_done = 0
    pending = 0.0  # closing kick owed by the last step, merged into the next first kick
    stepped = 0
    for n in range(n_steps):
        t = n * dt
        if n_frames > 0:
            for i in range(nb):
                u_old[i] = u[i]
                v_old[i] = v[i]
        us_old = 0.0
        fe_old = 0.0
        if has_sched:
            us_old = u[sched_body]
            fe_old = schedule_force(t, sched_t, sched_f)
        if dissipative:  # E(dt/2) S(dt) E(dt/2): each step ends synchronised
            dissipate(u2, v2, m2, im2, A2, d02, con3, law, state3, hold, slip, viscous, holder, viscous_rate, 0.5 * dt,
                      wall_slot, work, lost, j_visc, j_holder)
        reach = min(nb, still + n_drift + 2)
        stepped += reach
        step(u, v, invm, f, A, d0, load, law, expo, state3, A_el, d0_el, a_coef, b_coef, dt, t, pending, head, sub,
             multirate, sched_body, sched_t, sched_f, wall_slot, heads, h_work, h_busy, impulses, reach)
        t_new = (n + 1) * dt
        pending = b_coef[n_drift] * dt
        check = (n + 1) % check_every == 0 or n == n_steps - 1
        if check or n_frames > 0 or dissipative:  # synchronise every velocity
            if wall_slot > 0:
                impulses[0] += pending * f[wall_slot]
            impulses[1] += external_kick(v, invm, pending, t_new, sched_body, sched_t, sched_f)
            closing_kick(v, invm, f, pending, head, reach)
            pending = 0.0
        if still < nb:
            still = still_from(u2, v2, u_rest, still, reach)
        if dissipative:
            dissipate(u2, v2, m2, im2, A2, d02, con3, law, state3, hold, slip, viscous, holder, viscous_rate, 0.5 * dt,
                      wall_slot, work, lost, j_visc, j_holder)
        if has_sched:
            fe_new = schedule_force(t_new, sched_t, sched_f)
            w_sched += 0.5 * (fe_old + fe_new) * (u[sched_body] - us_old)
        else:
            fe_new = 0.0
        steps_done = n + 1

        probe_overlaps(u2, v2, im2, f2, d02, ch_slot, ch_weight, pending, head, sched_body, fe_new, d_new, r_new)
        while j_out < n_out and j_out * sample_dt <= t_new * (1.0 + 1e-12):
            x = (j_out * sample_dt - t) / dt
            hermite_weights(x, dt, w, 0)
            for c in range(n_ch):
                out[c, j_out] = recorded_force(w, 0, x, c, 0, ch_slot, ch_weight, A2, con3, law, state3,
                                               d_old, r_old, d_new, r_new)
            j_out += 1
        if law == PLASTIC:  # the contacts' memory renewed at the step's end, after its records
            plastic_commit(u2, v2, im2, f2, A2, d02, con3, state3, pending, head, sched_body, fe_new, dt, reach,
                           every)
        d_old, d_new = d_new, d_old  # this step's end is the next one's start
        r_old, r_new = r_new, r_old
        while j_frame < n_frames and j_frame * frame_dt <= t_new * (1.0 + 1e-12):
            hermite_weights((j_frame * frame_dt - t) / dt, dt, w, 0)
            for i in range(nb):
                frames[j_frame, i] = hermite(w, 0, u_old[i], v_old[i], u[i], v[i])
            j_frame += 1

        if check:
            state_sums(heads[0], heads[1], m2, b2, heads[4], con3[0], heads[5], dl2, law, state3, sums[0:1],
                       sums[1:2], sums[2:3])
            e = sums[0] - w_sched + lost[0]
            err = abs(e - e0) / e_ref
            j_wall = impulses[0] + j_visc[0]
            pe = abs(sums[1] - p0 - (t_new * net_const + impulses[1] - j_wall + j_holder[0])) / p_ref
            if not (err < 1e300) or not (sums[2] <= 1.0):
                status = 1
                break
            e_err = max(e_err, err)
            p_err = max(p_err, pe)

    diag[ENERGY_ERROR] = e_err
    diag[MOMENTUM_ERROR] = p_err
    diag[WALL_IMPULSE] = impulses[0] + j_visc[0] + wall_load * steps_done * dt
    diag[STATUS] = status
    diag[STEPS] = steps_done
    diag[END_TIME] = steps_done * dt
    diag[DISSIPATED] = lost[0]
    if law == PLASTIC:
        diag[DISSIPATED] += plastic_work(state3, 0)
    diag[BODIES_STEPPED] = stepped
