"""DOP853 on the chain, compiled: the explicit Runge-Kutta method of order 8 by Dormand and
Prince with Hairer's 5th/3rd-order error estimate, step-size control and 7th-order dense
output, recording one contact force on a uniform output grid.

E. Hairer, S. P. Norsett, G. Wanner, *Solving Ordinary Differential Equations I: Nonstiff
Problems*, 2nd ed., Springer 1993, Sec. II.5 (the method), II.4 (step-size control, the
starting step) and II.6 (dense output), and their Fortran code DOP853 (the constants below
keep its names: c_i, a_ij, b_i, bhh_i, er_i, d_ij; stage i here is row i - 1).

The system y' = F(y), y = [u, v] (m, m/s, size 2 nb):

    du_i/dt = v_i,   dv_i/dt = (f[i] - f[i+1]) invm[i],
    f[i] = A[i] max(d0[i] + u[i-1] - u[i], 0)^(3/2) - load[i],  f[0] = 0,  f[nb] = -load[nb]

(the dynamic Hertz forces of rig.solver.kernels.forces.hertz_forces, N).

One step of size h from (t, y): stages k_1 = F(y) (the last stage of the step before),
k_s = F(y + h sum_{j<s} a_sj k_j), s = 2..12; y_new = y + h sum_i b_i k_i (order 8).
Error (Hairer's combined estimate, per component i, sk_i = atol_i + rtol max(|y_i|, |y_new,i|)):

    err5_i = sum_j er_j k_j,  err3_i = sum_j (b_j - bhh_j) k_j,
    err = |h| sum (err5_i/sk_i)^2 / sqrt(n (sum (err5_i/sk_i)^2 + 0.01 sum (err3_i/sk_i)^2))

A step with err <= 1 is accepted and k_13 = F(y_new) is its derivative at the end (the next
step's k_1). New step h_new = h / max(1/6, min(1/0.333, err^(1/8) / 0.9)) (so 0.333 <= h_new/h
<= 6), after a rejection h_new <= h; a rejected step is retried with
h / min(1/0.333, err^(1/8) / 0.9). A step that would end within 1 % of t_end is stretched to it.

Dense output on a step (theta = (t_out - t) / h in [0, 1]):

    y(t_out) = y + theta (r1 + (1 - theta) (r2 + theta (r3 + (1 - theta) (r4 + theta (r5
               + (1 - theta) (r6 + theta r7))))))
    r1 = y_new - y,  r2 = h k_1 - r1,  r3 = r1 - h k_13 - r2,  r_{m+4} = h sum_j d_{m+4,j} k_j

where the sums d run over 16 stages: the 13 above and three more (c = 0.1, 0.2, 7/9), computed
only for steps that contain an output point, and the polynomial is evaluated only for the two
displacements the recorded contact needs.
"""
import math

import numpy as np

from numerics.jit import jit

# B and C, unused here, are re-exported: tests/bench/test_peers.py holds the whole table to scipy's
from rig.bench.kernels.dop853_table import E3, E5, N_STAGES, N_STAGES_EXTENDED, A, B, C, D  # noqa: F401
from rig.solver.kernels.forces import hertz_forces

SAFETY = 0.9            # Hairer's safe
FAC1 = 0.333            # h_new / h >= FAC1
FAC2 = 6.0              # h_new / h <= FAC2
UROUND = 2.3e-16        # the rounding unit of DOP853's step-too-small test

# the outcome codes of integrate (counts[STATUS])
SUCCESS = 0
STEP_TOO_SMALL = 1
# counts: what integrate did
EVALUATIONS, ACCEPTED, REJECTED, DENSE_STEPS, STATUS = range(5)


@jit
def chain_rhs(y, A_hertz, d0, load, invm, f, dy):
    """dy = F(y) (m/s, m/s^2) for the chain's state y = [u, v] (module doc); f (size nb + 1)
    holds the dynamic forces (N), f[0] = 0 and f[nb] = -load[nb] set by the caller."""
    nb = invm.shape[0]
    hertz_forces(y[:nb], A_hertz, d0, load, f)
    for i in range(nb):
        dy[i] = y[nb + i]
        dy[nb + i] = (f[i] - f[i + 1]) * invm[i]


@jit
def stage_argument(y, k, s, h, out):
    """out = y + h sum_{j<s} A[s, j] k[j]: the argument of stage s (0-based row of A)."""
    n = y.shape[0]
    for i in range(n):
        out[i] = y[i]
    for j in range(s):
        a = A[s, j] * h
        if a != 0.0:
            for i in range(n):
                out[i] += a * k[j, i]


@jit
def error_norm(y, y_new, k, h, rtol, atol, e5, e3):
    """Hairer's combined error of a step (module doc; <= 1: accept). e5, e3: scratch (2 nb),
    filled with the 5th- and 3rd-order error estimates sum_j er_j k_j, sum_j (b_j - bhh_j) k_j."""
    n = y.shape[0]
    for i in range(n):
        e5[i] = 0.0
        e3[i] = 0.0
    for j in range(N_STAGES):
        if E5[j] != 0.0:
            for i in range(n):
                e5[i] += E5[j] * k[j, i]
        if E3[j] != 0.0:
            for i in range(n):
                e3[i] += E3[j] * k[j, i]
    err5 = 0.0
    err3 = 0.0
    for i in range(n):
        sk = atol[i] + rtol * max(abs(y[i]), abs(y_new[i]))
        q5 = e5[i] / sk
        q3 = e3[i] / sk
        err5 += q5 * q5
        err3 += q3 * q3
    deno = err5 + 0.01 * err3
    if deno <= 0.0:
        deno = 1.0
    return abs(h) * err5 * math.sqrt(1.0 / (n * deno))


@jit
def rms(x, scale):
    """sqrt(mean((x / scale)^2)) (Hairer's norm of the starting step, Sec. II.4)."""
    total = 0.0
    for i in range(x.shape[0]):
        q = x[i] / scale[i]
        total += q * q
    return math.sqrt(total / x.shape[0])


@jit
def starting_step(y, k, t_end, rtol, atol, A_hertz, d0, load, invm, f, work, scale):
    """The first step (s) by Hairer's rule (Sec. II.4, 8th order, the norms as scipy's):
    h0 = 0.01 |y|/|F(y)| (1e-6 s for tiny norms), one Euler step of h0 to estimate the
    second derivative d2, then h = min(100 h0, (0.01 / max(|F(y)|, d2))^(1/8), t_end).
    Uses k[0] = F(y) and one evaluation of F into k[1]; scale and work are scratch."""
    n = y.shape[0]
    for i in range(n):
        scale[i] = atol[i] + abs(y[i]) * rtol
    n0 = rms(y, scale)
    n1 = rms(k[0], scale)
    h0 = 1e-6 if n0 < 1e-5 or n1 < 1e-5 else 0.01 * n0 / n1
    h0 = min(h0, t_end)
    for i in range(n):
        work[i] = y[i] + h0 * k[0, i]
    chain_rhs(work, A_hertz, d0, load, invm, f, k[1])
    for i in range(n):
        work[i] = k[1, i] - k[0, i]
    n2 = rms(work, scale) / h0
    h1 = max(1e-6, h0 * 1e-3) if n1 <= 1e-15 and n2 <= 1e-15 else (0.01 / max(n1, n2)) ** (1.0 / 8.0)
    return min(100.0 * h0, h1, t_end)


@jit
def probe_force(A_hertz, d0, slot, u_above, u_below):
    """The whole contact force of slot ``slot`` (N): A max(d0 + u_above - u_below, 0)^(3/2)."""
    d = d0[slot] + u_above - u_below
    d = d if d > 0.0 else 0.0
    return A_hertz[slot] * d * math.sqrt(d)


@jit
def dense_coefficients(y, y_new, k, h, i, r):
    """r[0..6] = r1..r7 of the dense output (module doc) for component i of the state."""
    r[0] = y_new[i] - y[i]
    r[1] = h * k[0, i] - r[0]
    r[2] = r[0] - h * k[N_STAGES, i] - r[1]
    for m in range(4):
        total = 0.0
        for j in range(N_STAGES_EXTENDED):
            total += D[m, j] * k[j, i]
        r[3 + m] = h * total


@jit
def dense_value(y0, r, theta):
    """The dense output at theta = (t - t_old) / h from r1..r7 (module doc)."""
    s1 = 1.0 - theta
    return y0 + theta * (r[0] + s1 * (r[1] + theta * (r[2] + s1 * (r[3] + theta * (
        r[4] + s1 * (r[5] + theta * r[6]))))))


@jit
def integrate(y, t_end, rtol, atol, A_hertz, d0, load, invm, slot, sample_interval,
              out, k, y_new, work, f, counts):
    """DOP853 (module doc) from t = 0 to t_end (s), y = [u, v] advanced in place; records the
    contact force of ``slot`` (N, probe_force) at t_j = j sample_interval into out[j].

    atol (size 2 nb): absolute tolerances (m, m/s); rtol: relative tolerance. Scratch: k
    (16, 2 nb), y_new (2 nb), work (2, 2 nb), f (nb + 1). counts (int64, 5) receives the
    numbers of evaluations of F, of accepted and of rejected steps, of steps with an output
    point, and the status (SUCCESS, or STEP_TOO_SMALL when h fell below the rounding of t).
    """
    n = y.shape[0]
    nb = n // 2
    above, below = slot - 1, slot  # the displacements u[slot - 1], u[slot] are y[slot - 1], y[slot]
    r_above = np.zeros(7)
    r_below = np.zeros(7)
    n_out = out.shape[0]
    f[0] = 0.0
    f[nb] = -load[nb]
    chain_rhs(y, A_hertz, d0, load, invm, f, k[0])
    h = starting_step(y, k, t_end, rtol, atol, A_hertz, d0, load, invm, f, work[0], work[1])
    counts[EVALUATIONS] = 2
    counts[ACCEPTED] = 0
    counts[REJECTED] = 0
    counts[DENSE_STEPS] = 0
    counts[STATUS] = SUCCESS
    out[0] = probe_force(A_hertz, d0, slot, y[above], y[below])
    j_out = 1
    t = 0.0
    h_max = t_end
    reject = False
    last = False
    while not last:
        if 0.1 * abs(h) <= abs(t) * UROUND:
            counts[STATUS] = STEP_TOO_SMALL
            return
        if t + 1.01 * h - t_end > 0.0:
            h = t_end - t
            last = True
        for s in range(1, N_STAGES):
            stage_argument(y, k, s, h, work[0])
            chain_rhs(work[0], A_hertz, d0, load, invm, f, k[s])
        stage_argument(y, k, N_STAGES, h, y_new)
        counts[EVALUATIONS] += N_STAGES - 1
        err = error_norm(y, y_new, k, h, rtol, atol, work[0], work[1])
        fac11 = err ** 0.125
        if err <= 1.0:
            fac = max(1.0 / FAC2, min(1.0 / FAC1, fac11 / SAFETY))
            h_new = h / fac
            chain_rhs(y_new, A_hertz, d0, load, invm, f, k[N_STAGES])
            counts[EVALUATIONS] += 1
            counts[ACCEPTED] += 1
            t_new = t_end if last else t + h
            if j_out < n_out and (last or j_out * sample_interval <= t_new):
                for s in range(N_STAGES + 1, N_STAGES_EXTENDED):
                    stage_argument(y, k, s, h, work[0])
                    chain_rhs(work[0], A_hertz, d0, load, invm, f, k[s])
                counts[EVALUATIONS] += N_STAGES_EXTENDED - N_STAGES - 1
                counts[DENSE_STEPS] += 1
                dense_coefficients(y, y_new, k, h, above, r_above)
                dense_coefficients(y, y_new, k, h, below, r_below)
                while j_out < n_out and (last or j_out * sample_interval <= t_new):
                    theta = min((j_out * sample_interval - t) / h, 1.0)
                    out[j_out] = probe_force(A_hertz, d0, slot, dense_value(y[above], r_above, theta),
                                             dense_value(y[below], r_below, theta))
                    j_out += 1
            for i in range(n):
                k[0, i] = k[N_STAGES, i]
                y[i] = y_new[i]
            t = t_new
            if abs(h_new) > h_max:
                h_new = h_max
            if reject:
                h_new = min(abs(h_new), abs(h))
            reject = False
        else:
            h_new = h / min(1.0 / FAC1, fac11 / SAFETY)
            reject = True
            last = False
            counts[REJECTED] += 1
        h = h_new
