"""Many shots of one chain topology at once (numba): shots are the innermost index.

Arrays are (chunks, bodies, width): each chunk is a C-contiguous block whose inner index
runs over ``width`` shots from 0, so every loop over the shots of a chunk vectorises;
``integrate_ensemble`` runs the chunks on as many threads as numba's. Every shot
performs exactly the operations of the single-shot kernel (integrators.integrate) in the
same order with the same step, so the two agree to the last bit (the multirate head
runs the same multirate.head_flow in both; the viscous contacts and the holder's drag and
friction the same dissipation.dissipate). Constant loads only (no force schedule).

The passes over a chunk's rows are ensemble_passes.py's.
"""
import math

import numpy as np

from numerics.jit import jit
from numerics.threads import over_threads
from rig.model.contact import HERTZ, PLASTIC
from rig.solver.kernels import report as slot
from rig.solver.kernels.dissipation import dissipate, holder_factors
from rig.solver.kernels.ensemble_passes import kick_drift, kick_drift_forces, shot_forces
from rig.solver.kernels.forces import contact_force, plastic_contact, state_sums
from rig.solver.kernels.integrators import rest_from, still_from
from rig.solver.kernels.memory import other_exponent, plastic_commit, plastic_work
from rig.solver.kernels.record import hermite_weights, probe_overlaps


@jit
def _record(out, lo, j0, nj, w, x, ch_slot, ch_weight, A, law, con, state, d_old, r_old, d_new, r_new):
    """out[lo + s, c, j0 + m] for m < nj: channel c's force (N) of every shot s of the chunk
    (its last ones may be fill, not in out) at the step's m-th sample, at fraction x[m] of
    the step, whose Hermite weights are column m of w: record.recorded_force's operations,
    in its order (0 + the first term is that term: no force is -0). The samples of a step
    are innermost: the Hertz loop vectorises over them, and each shot's channel is written
    as one contiguous run of its record. ``state``: the contacts' memory (PLASTIC)."""
    n_ch = ch_slot.shape[0]
    for s in range(min(d_old.shape[2], out.shape[0] - lo)):
        for c in range(n_ch):
            o = out[lo + s, c, j0:j0 + nj]
            first = True
            for k in range(ch_slot.shape[1]):
                wk = ch_weight[c, k]
                if wk != 0.0:
                    i = ch_slot[c, k]
                    a = A[i, s]
                    y0, r0, y1, r1 = d_old[c, k, s], r_old[c, k, s], d_new[c, k, s], r_new[c, k, s]
                    for m in range(nj):
                        d = w[0, m] * y0 + w[1, m] * r0 + w[2, m] * y1 + w[3, m] * r1
                        if law == HERTZ:
                            d = d if d > 0.0 else 0.0
                            fk = wk * (a * d * math.sqrt(d))
                        elif law == PLASTIC:
                            rate = (1.0 - x[m]) * r0 + x[m] * r1
                            fc, _ = plastic_contact(d, rate, a, con[0, i, s], con[2, i, s], state, i, s)
                            fk = wk * fc
                        else:
                            rate = (1.0 - x[m]) * r0 + x[m] * r1
                            fc, _ = contact_force(d, rate, a, con[0, i, s], con[1, i, s], con[2, i, s],
                                                  con[3, i, s], law)
                            fk = wk * fc
                        o[m] = fk if first else o[m] + fk
                    first = False
            if first:  # a channel of no contact records nothing
                for m in range(nj):
                    o[m] = 0.0


@jit(nogil=True)
def integrate_chunks(first, last, u3, v3, chain, contacts, holder, method, record, checks, diag3):
    """Integrate the shots of chunks first .. last - 1 of the (chunks, bodies, width) arrays
    u3 (m) and v3 (m/s) in place (integrate_ensemble's arguments), without the GIL: each
    thread runs one range of chunks, in one call (a call from Python types its bundles
    again: one per thread, not one per chunk). One function, the chunk's loop within it:
    numba links a callee's machine code into its caller's and optimises it again, so a
    function per chunk had cost the batched solver's whole tree a second time (2.7 s of a
    cold rig mc's compile)."""
    mass3, invm3, bias3, load3, A3, d03, d_limit3 = chain  # each bundle's fields, in their order (bundles.py)
    law, con3, state3 = contacts
    onsite3, slip, viscous_rate, flows = holder
    a_coef, b_coef, dt, n_steps, head, sub, multirate = method
    ch_slot, ch_weight, sample_dt, out = record.ch_slot, record.ch_weight, record.sample_dt, record.out
    check_every, e_ref3, p_ref3, wall_slot = checks.check_every, checks.e_ref, checks.p_ref, checks.wall_slot
    n_ch = ch_slot.shape[0]
    for k in range(first, last):
        # chunk k's (bodies, width) arrays, its shots k W .. (k + 1) W - 1 in out
        u, v, mass, invm, bias, load, A, d0 = u3[k], v3[k], mass3[k], invm3[k], bias3[k], load3[k], A3[k], d03[k]
        con, state, onsite, d_limit = con3[k], state3[k], onsite3[k], d_limit3[k]
        e_ref, p_ref, diag = e_ref3[k], p_ref3[k], diag3[k]
        nb, W = u.shape
        lo = k * W
        f = np.zeros((nb + 1, W))
        d_old = np.zeros((n_ch, ch_slot.shape[1], W))
        r_old = np.zeros((n_ch, ch_slot.shape[1], W))
        d_new = np.zeros((n_ch, ch_slot.shape[1], W))
        r_new = np.zeros((n_ch, ch_slot.shape[1], W))
        n_drift = a_coef.shape[0]
        n_out = out.shape[2]
        viscous = False
        holder = False
        for i in range(nb):
            for s in range(W):
                viscous = viscous or con[1, i, s] != 0.0 or con[2, i, s] != 0.0
                holder = holder or onsite[0, i, s] != 0.0 or onsite[1, i, s] != 0.0
        dissipative = flows  # a constant (bundles.Holder): a chain without flows compiles no dissipation
        every = other_exponent(A, con)  # PLASTIC: every slot renewed at every stage (memory.plastic_commit)
        work = np.zeros((5, nb + 1, W))  # the dissipation's work arrays
        hold = holder_factors(onsite, 0.5 * dt, viscous)  # E(dt/2)'s holder flows
        lost = np.zeros(W)  # the energy dissipation took (J), its impulse on the wall and the holder's (N s)
        j_visc = np.zeros(W)
        j_holder = np.zeros(W)
        for s in range(W):
            f[0, s] = 0.0
            f[nb, s] = -load[nb, s]
        shot_forces(u, A, d0, load, f, law, con, state)
        e0 = np.empty(W)
        p0 = np.empty(W)
        e = np.empty(W)
        pn = np.empty(W)
        worst = np.empty(W)
        net = np.empty(W)
        j_wall = np.zeros(W)
        w = np.empty((4, int(dt / sample_dt) + 2))  # Hermite weights of the samples of one step
        x = np.empty(w.shape[1])  # their fractions of the step
        h_work, h_busy = np.empty((2, 3, head + 1, W)), np.empty((5 + head, W))  # the head flow's work arrays
        state_sums(u, v, mass, bias, A, con[0], d0, d_limit, law, state, e0, p0, worst)
        for s in range(W):
            net[s] = load[nb, s] - (load[wall_slot, s] if wall_slot > 0 else 0.0)
        probe_overlaps(u, v, invm, f, d0, ch_slot, ch_weight, 0.0, head, -1, 0.0, d_old, r_old)
        u_rest = u.copy()
        still = nb
        if not dissipative:
            still = 1
            for s in range(W):
                still = max(still, rest_from(v[:, s], invm[:, s], f[:, s], head + 1))
        if n_out > 0:
            hermite_weights(0.0, dt, w, 0)
            x[0] = 0.0
            _record(out, lo, 0, 1, w, x, ch_slot, ch_weight, A, law, con, state, d_old, r_old, d_old, r_old)
        j_out = 1
        pending = 0.0
        stepped = 0
        for n in range(n_steps):
            t = n * dt
            reach = min(nb, still + n_drift + 2)
            stepped += reach
            if dissipative:  # E(dt/2) S(dt) E(dt/2) (integrators.integrate)
                dissipate(u, v, mass, invm, A, d0, con, law, state, hold, slip, viscous, holder, viscous_rate, 0.5 * dt,
                          wall_slot, work, lost, j_visc, j_holder)
            for st in range(n_drift):
                hb = b_coef[st] * dt
                if st == 0:
                    hb += pending
                if wall_slot > 0:
                    for s in range(W):
                        j_wall[s] += hb * f[wall_slot, s]
                h = a_coef[st] * dt
                kick_drift_forces(u, v, invm, f, A, d0, load, hb, h, head, multirate, a_coef, b_coef, sub[st], h_work,
                                  h_busy, law, con, state, reach)
            t_new = (n + 1) * dt
            pending = b_coef[n_drift] * dt
            check = (n + 1) % check_every == 0 or n == n_steps - 1
            if check or dissipative:
                if wall_slot > 0:
                    for s in range(W):
                        j_wall[s] += pending * f[wall_slot, s]
                kick_drift(u, v, invm, f, pending, 0.0, head, reach)
                pending = 0.0
            if still < nb:
                still = still_from(u, v, u_rest, still, reach)
            if dissipative:
                dissipate(u, v, mass, invm, A, d0, con, law, state, hold, slip, viscous, holder, viscous_rate, 0.5 * dt,
                          wall_slot, work, lost, j_visc, j_holder)
            probe_overlaps(u, v, invm, f, d0, ch_slot, ch_weight, pending, head, -1, 0.0, d_new, r_new)
            j_end = j_out
            while j_end < n_out and j_end * sample_dt <= t_new * (1.0 + 1e-12):
                j_end += 1
            for j in range(j_out, j_end):  # the weights are the same for every shot and channel
                x[j - j_out] = (j * sample_dt - t) / dt
                hermite_weights(x[j - j_out], dt, w, j - j_out)
            _record(out, lo, j_out, j_end - j_out, w, x, ch_slot, ch_weight, A, law, con, state, d_old, r_old, d_new,
                    r_new)
            if law == PLASTIC:  # the contacts' memory renewed at the step's end, after its records
                plastic_commit(u, v, invm, f, A, d0, con, state, pending, head, -1, 0.0, dt, reach, every)
            j_out = j_end
            for c in range(d_old.shape[0]):  # element by element (numba compiles a slice copy's error message)
                for q in range(d_old.shape[1]):
                    for s in range(W):
                        d_old[c, q, s] = d_new[c, q, s]
                        r_old[c, q, s] = r_new[c, q, s]
            if check:
                state_sums(u, v, mass, bias, A, con[0], d0, d_limit, law, state, e, pn, worst)
                for s in range(W):
                    err = abs(e[s] + lost[s] - e0[s]) / e_ref[s]
                    pe = abs(pn[s] - p0[s] - (t_new * net[s] - (j_wall[s] + j_visc[s]) + j_holder[s])) / p_ref[s]
                    if not (err < 1e300) or not (worst[s] <= 1.0):
                        diag[slot.STATUS, s] = 1.0
                    diag[slot.ENERGY_ERROR, s] = max(diag[slot.ENERGY_ERROR, s], err)
                    diag[slot.MOMENTUM_ERROR, s] = max(diag[slot.MOMENTUM_ERROR, s], pe)
        for s in range(W):
            wall_load = load[wall_slot, s] if wall_slot > 0 else 0.0
            diag[slot.WALL_IMPULSE, s] = j_wall[s] + j_visc[s] + wall_load * n_steps * dt
            diag[slot.STEPS, s] = n_steps
            diag[slot.END_TIME, s] = n_steps * dt
            diag[slot.DISSIPATED, s] = lost[s]
            if law == PLASTIC:
                diag[slot.DISSIPATED, s] += plastic_work(state, s)
            diag[slot.BODIES_STEPPED, s] = stepped


def integrate_ensemble(u, v, chain, contacts, holder, method, record, checks, diag):
    """Integrate every shot of the (chunks, bodies, width) arrays u (m) and v (m/s) in
    place; the bundles are bundles.py's, their arrays with the chunk axis first and the
    shots innermost: chain's (chunks, bodies, width), contacts.con (chunks, 6, bodies,
    width), contacts.state (chunks, STATE_ROWS, bodies, width: the contacts' memory, renewed),
    holder.onsite (chunks, 2, bodies, width), checks.e_ref and p_ref (chunks, width);
    record.out is (shots, channels, samples), each shot's record contiguous, chunk k
    holding shots k width .. (k + 1) width - 1 (fill past the last shot); record.frames is
    not read. diag is (chunks, report.DIAGNOSTICS, width), each shot's column as the
    single-shot kernel's diag.

    The chunks are shared out over as many threads as numba's (numba.get_num_threads) in
    contiguous ranges, each thread running integrate_chunks over its range: a numba parallel
    loop over them compiled the chunk's whole kernel twice more (its gufunc and its caller
    each link and re-optimise it), the largest part of a cold rig mc's compile time."""
    over_threads(u.shape[0], integrate_chunks, u, v, chain, contacts, holder, method, record, checks, diag)
