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

With a multirate head (head > 0, see rig/stepsize.py) the kicks carry every contact but
the first ``head`` ones, and each drift moves bodies 0..head by multirate.head_flow
(``sub[s]`` substeps of the same method in drift s) instead of a plain drift.
"""
import numpy as np

from instruments.jit import jit
from rig.solver.kernels.forces import contact_forces, energy, force_rate, max_overlap_excess, momentum
from rig.solver.kernels.multirate import head_flow, slow_net


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


@jit
def _external_kick(v, invm, f, h, t, wall_slot, sched_body, sched_t, sched_f):
    """Kick by the scheduled force; returns (dynamic wall impulse, schedule impulse)."""
    j_wall = h * f[wall_slot] if wall_slot > 0 else 0.0
    j_sched = 0.0
    if sched_t.shape[0] > 0:
        fe = schedule_force(t, sched_t, sched_f)
        v[sched_body] += h * fe * invm[sched_body]
        j_sched = h * fe
    return j_wall, j_sched


@jit
def _kick_drift(u, v, invm, f, hb, ha, head):
    """One pass: v += hb (f_above - f_below)/m, then u += ha v (ha = 0: kick only). With a
    head, bodies 0..head get only the kick of slot head + 1 and are not drifted here."""
    start = 0
    if head > 0:
        v[head] += hb * (0.0 - f[head + 1]) * invm[head]
        start = head + 1
    for i in range(start, v.shape[0]):
        vi = v[i] + hb * (f[i] - f[i + 1]) * invm[i]
        v[i] = vi
        u[i] += ha * vi


@jit
def _synced_velocity(j, v, invm, f2, pending, sched_body, f_sched, head):
    """Velocity of body j once the owed closing kick of ``pending`` seconds is applied
    (f2: the forces as a (slots, 1) view)."""
    vj = v[j] + pending * slow_net(f2, j, head, 0) * invm[j]
    if j == sched_body:
        vj += pending * f_sched * invm[j]
    return vj


@jit
def _probe(f, load, u, v, invm, A, d0, ch_slot, ch_weight, pending, sched_body, f_sched, head, y, r):
    """Channel values y (N, whole contact forces) and rates r (N/s) at a step end."""
    f2 = f.reshape((f.shape[0], 1))
    for c in range(ch_slot.shape[0]):
        y[c] = 0.0
        r[c] = 0.0
        for k in range(ch_slot.shape[1]):
            w = ch_weight[c, k]
            if w != 0.0:
                s = ch_slot[c, k]
                y[c] += w * (f[s] + load[s])
                va = _synced_velocity(s - 1, v, invm, f2, pending, sched_body, f_sched, head)
                vb = _synced_velocity(s, v, invm, f2, pending, sched_body, f_sched, head)
                r[c] += w * force_rate(s, u, va, vb, A, d0)


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
def integrate(u, v, mass, invm, bias, load, A, d0, damping, law,
              a_coef, b_coef, dt, n_steps, head, sub,
              sched_body, sched_t, sched_f,
              ch_slot, ch_weight, sample_dt, out,
              frame_dt, frames,
              check_every, d_limit, wall_slot, e_ref, p_ref, diag):
    """Integrate n_steps of size dt in place; fill out (n_ch, n_out) and frames (n_fr, nb).

    diag (float64[6]) receives: max relative energy error, max relative momentum balance
    error, total wall impulse (N s), status (0 ok, 1 unstable), steps done, final time.
    Energy: E = kinetic + elastic - work of constant loads - work of the scheduled force.
    Momentum balance: P(t) - P(0) - [t * sum(constant loads) + J_schedule - J_wall].
    load[i] (size nb + 1): constant force carried from above through slot i (N).
    """
    nb = u.shape[0]
    f = np.zeros(nb + 1)
    f[nb] = -load[nb]
    n_drift = a_coef.shape[0]
    n_ch = ch_slot.shape[0]
    n_out = out.shape[1]
    n_frames = frames.shape[0]
    has_sched = sched_t.shape[0] > 0

    contact_forces(u, v, A, d0, damping, law, load, f)
    # (bodies, 1) views for the multirate head (shared with the batched kernel)
    u2, v2, im2, f2 = u.reshape((nb, 1)), v.reshape((nb, 1)), invm.reshape((nb, 1)), f.reshape((nb + 1, 1))
    A2, d02, load2 = A.reshape((nb, 1)), d0.reshape((nb, 1)), load.reshape((nb + 1, 1))
    h_ns, h_work = np.empty(1, np.int64), np.empty((3, 1))  # the head's work arrays
    # sum of constant loads, less the part the wall's slot carries (j_wall is dynamic)
    wall_load = load[wall_slot] if wall_slot > 0 else 0.0
    net_const = load[nb] - wall_load
    e0 = energy(u, v, mass, bias, A, d0)
    p0 = momentum(v, mass)
    j_wall = 0.0
    j_sched = 0.0
    w_sched = 0.0

    y_old = np.empty(n_ch)
    r_old = np.empty(n_ch)
    y_new = np.empty(n_ch)
    r_new = np.empty(n_ch)
    w = np.empty((4, 1))
    _probe(f, load, u, v, invm, A, d0, ch_slot, ch_weight, 0.0, sched_body, 0.0, head, y_old, r_old)
    if n_out > 0:
        for c in range(n_ch):
            out[c, 0] = y_old[c]
    j_out = 1
    u_old = np.empty(nb if n_frames > 0 else 0)
    v_old = np.empty(nb if n_frames > 0 else 0)
    if n_frames > 0:
        frames[0, :] = u
    j_frame = 1

    e_err = 0.0
    p_err = 0.0
    status = 0
    steps_done = 0
    pending = 0.0  # closing kick owed by the last step, merged into the next first kick
    for n in range(n_steps):
        t = n * dt
        if n_frames > 0:
            u_old[:] = u
            v_old[:] = v
        us_old = 0.0
        fe_old = 0.0
        if has_sched:
            us_old = u[sched_body]
            fe_old = schedule_force(t, sched_t, sched_f)
        ts = t
        for s in range(n_drift):
            hb = b_coef[s] * dt
            if s == 0:
                hb += pending
            jw, js = _external_kick(v, invm, f, hb, ts, wall_slot,
                                    sched_body, sched_t, sched_f)
            j_wall += jw
            j_sched += js
            h = a_coef[s] * dt
            _kick_drift(u, v, invm, f, hb, h, head)
            if head > 0:
                head_flow(u2, v2, im2, f2, A2, d02, load2, head, a_coef, b_coef, h, sub[s], h_ns, h_work)
            ts += h
            contact_forces(u, v, A, d0, damping, law, load, f)
        t_new = (n + 1) * dt
        pending = b_coef[n_drift] * dt
        check = (n + 1) % check_every == 0 or n == n_steps - 1
        if check or n_frames > 0:  # synchronise every velocity
            jw, js = _external_kick(v, invm, f, pending, t_new, wall_slot,
                                    sched_body, sched_t, sched_f)
            j_wall += jw
            j_sched += js
            _kick_drift(u, v, invm, f, pending, 0.0, head)
            pending = 0.0
        if has_sched:
            fe_new = schedule_force(t_new, sched_t, sched_f)
            w_sched += 0.5 * (fe_old + fe_new) * (u[sched_body] - us_old)
        else:
            fe_new = 0.0
        steps_done = n + 1

        _probe(f, load, u, v, invm, A, d0, ch_slot, ch_weight, pending, sched_body, fe_new, head,
               y_new, r_new)
        while j_out < n_out and j_out * sample_dt <= t_new * (1.0 + 1e-12):
            hermite_weights((j_out * sample_dt - t) / dt, dt, w, 0)
            for c in range(n_ch):
                out[c, j_out] = hermite(w, 0, y_old[c], r_old[c], y_new[c], r_new[c])
            j_out += 1
        for c in range(n_ch):
            y_old[c] = y_new[c]
            r_old[c] = r_new[c]
        while j_frame < n_frames and j_frame * frame_dt <= t_new * (1.0 + 1e-12):
            hermite_weights((j_frame * frame_dt - t) / dt, dt, w, 0)
            for i in range(nb):
                frames[j_frame, i] = hermite(w, 0, u_old[i], v_old[i], u[i], v[i])
            j_frame += 1

        if check:
            e = energy(u, v, mass, bias, A, d0) - w_sched
            err = abs(e - e0) / e_ref
            pe = abs(momentum(v, mass) - p0 - (t_new * net_const + j_sched - j_wall)) / p_ref
            if not (err < 1e300) or not (max_overlap_excess(u, d0, d_limit) <= 1.0):
                status = 1
                break
            e_err = max(e_err, err)
            p_err = max(p_err, pe)

    diag[0] = e_err
    diag[1] = p_err
    diag[2] = j_wall + wall_load * steps_done * dt
    diag[3] = status
    diag[4] = steps_done
    diag[5] = steps_done * dt
