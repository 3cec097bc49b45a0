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

(the dynamic Hertz forces of rig.solver.kernels.forces.contact_forces, N).

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

from instruments.jit import jit
from rig.model.contact import HERTZ
from rig.solver.kernels.forces import contact_forces

N_STAGES = 12           # stages of one step (k_1 .. k_12); k_13 = F(y_new)
N_STAGES_EXTENDED = 16  # with the three extra stages of the dense output
SAFETY = 0.9            # Hairer's safe
FAC1 = 0.333            # h_new / h >= FAC1
FAC2 = 6.0              # h_new / h <= FAC2
UROUND = 2.3e-16        # the rounding unit of DOP853's step-too-small test

# --- the coefficients (Hairer and Wanner's DOP853, 1993) ---------------------------------
C = np.zeros(N_STAGES_EXTENDED)  # nodes c_1 .. c_16 (the chain's F does not depend on t: the table alone)
C[1:12] = [0.526001519587677318785587544488e-01, 0.789002279381515978178381316732e-01,
           0.118350341907227396726757197510, 0.281649658092772603273242802490,
           0.333333333333333333333333333333, 0.25, 0.307692307692307692307692307692,
           0.651282051282051282051282051282, 0.6, 0.857142857142857142857142857142, 1.0]
C[12] = 1.0                      # k_13 = F(y_new)
C[13:] = [0.1, 0.2, 0.777777777777777777777777777778]  # c14, c15, c16

A = np.zeros((N_STAGES_EXTENDED, N_STAGES_EXTENDED))  # A[s - 1, j - 1] = a_sj
A[1, [0]] = [5.26001519587677318785587544488e-2]  # a21
A[2, [0, 1]] = [1.97250569845378994544595329183e-2, 5.91751709536136983633785987549e-2]
A[3, [0, 2]] = [2.95875854768068491816892993775e-2, 8.87627564304205475450678981324e-2]
A[4, [0, 2, 3]] = [2.41365134159266685502369798665e-1, -8.84549479328286085344864962717e-1,
                   9.24834003261792003115737966543e-1]
A[5, [0, 3, 4]] = [3.7037037037037037037037037037e-2, 1.70828608729473871279604482173e-1,
                   1.25467687566822425016691814123e-1]
A[6, [0, 3, 4, 5]] = [3.7109375e-2, 1.70252211019544039314978060272e-1,
                      6.02165389804559606850219397283e-2, -1.7578125e-2]
A[7, [0, 3, 4, 5, 6]] = [3.70920001185047927108779319836e-2, 1.70383925712239993810214054705e-1,
                         1.07262030446373284651809199168e-1, -1.53194377486244017527936158236e-2,
                         8.27378916381402288758473766002e-3]
A[8, [0, 3, 4, 5, 6, 7]] = [6.24110958716075717114429577812e-1, -3.36089262944694129406857109825,
                            -8.68219346841726006818189891453e-1, 2.75920996994467083049415600797e1,
                            2.01540675504778934086186788979e1, -4.34898841810699588477366255144e1]
A[9, [0, 3, 4, 5, 6, 7, 8]] = [4.77662536438264365890433908527e-1, -2.48811461997166764192642586468,
                               -5.90290826836842996371446475743e-1, 2.12300514481811942347288949897e1,
                               1.52792336328824235832596922938e1, -3.32882109689848629194453265587e1,
                               -2.03312017085086261358222928593e-2]
A[10, [0, 3, 4, 5, 6, 7, 8, 9]] = [
    -9.3714243008598732571704021658e-1, 5.18637242884406370830023853209,
    1.09143734899672957818500254654, -8.14978701074692612513997267357,
    -1.85200656599969598641566180701e1, 2.27394870993505042818970056734e1,
    2.49360555267965238987089396762, -3.0467644718982195003823669022]
A[11, [0, 3, 4, 5, 6, 7, 8, 9, 10]] = [
    2.27331014751653820792359768449, -1.05344954667372501984066689879e1,
    -2.00087205822486249909675718444, -1.79589318631187989172765950534e1,
    2.79488845294199600508499808837e1, -2.85899827713502369474065508674,
    -8.87285693353062954433549289258, 1.23605671757943030647266201528e1,
    6.43392746015763530355970484046e-1]
A[12, [0, 5, 6, 7, 8, 9, 10, 11]] = [  # b1, b6 .. b12: y_new = y + h sum b_i k_i
    5.42937341165687622380535766363e-2, 4.45031289275240888144113950566,
    1.89151789931450038304281599044, -5.8012039600105847814672114227,
    3.1116436695781989440891606237e-1, -1.52160949662516078556178806805e-1,
    2.01365400804030348374776537501e-1, 4.47106157277725905176885569043e-2]
A[13, [0, 6, 7, 8, 9, 10, 11, 12]] = [
    5.61675022830479523392909219681e-2, 2.53500210216624811088794765333e-1,
    -2.46239037470802489917441475441e-1, -1.24191423263816360469010140626e-1,
    1.5329179827876569731206322685e-1, 8.20105229563468988491666602057e-3,
    7.56789766054569976138603589584e-3, -8.298e-3]
A[14, [0, 5, 6, 7, 10, 11, 12, 13]] = [
    3.18346481635021405060768473261e-2, 2.83009096723667755288322961402e-2,
    5.35419883074385676223797384372e-2, -5.49237485713909884646569340306e-2,
    -1.08347328697249322858509316994e-4, 3.82571090835658412954920192323e-4,
    -3.40465008687404560802977114492e-4, 1.41312443674632500278074618366e-1]
A[15, [0, 5, 6, 7, 8, 12, 13, 14]] = [
    -4.28896301583791923408573538692e-1, -4.69762141536116384314449447206,
    7.68342119606259904184240953878, 4.06898981839711007970213554331,
    3.56727187455281109270669543021e-1, -1.39902416515901462129418009734e-3,
    2.9475147891527723389556272149, -9.15095847217987001081870187138]
B = A[N_STAGES, :N_STAGES].copy()  # b_1 .. b_12

E3 = np.zeros(N_STAGES + 1)  # b_i - bhh_i: the 3rd-order error weights over k_1 .. k_13
E3[:N_STAGES] = B
E3[[0, 8, 11]] -= [0.244094488188976377952755905512, 0.733846688281611857341361741547,
                   0.220588235294117647058823529412e-1]  # bhh1 (k_1), bhh2 (k_9), bhh3 (k_12)

E5 = np.zeros(N_STAGES + 1)  # er_i: the 5th-order error weights over k_1 .. k_13
E5[[0, 5, 6, 7, 8, 9, 10, 11]] = [
    0.1312004499419488073250102996e-01, -0.1225156446376204440720569753e+01,
    -0.4957589496572501915214079952, 0.1664377182454986536961530415e+01,
    -0.3503288487499736816886487290, 0.3341791187130174790297318841,
    0.8192320648511571246570742613e-01, -0.2235530786388629525884427845e-01]

D = np.zeros((4, N_STAGES_EXTENDED))  # d_4j .. d_7j: the dense output's r4 .. r7 over k_1 .. k_16
DENSE_STAGES = [0, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15]  # the d_mj != 0: stages 1, 6 .. 16
D[0, DENSE_STAGES] = [-0.84289382761090128651353491142e+1, 0.56671495351937776962531783590,
              -0.30689499459498916912797304727e+1, 0.23846676565120698287728149680e+1,
              0.21170345824450282767155149946e+1, -0.87139158377797299206789907490,
              0.22404374302607882758541771650e+1, 0.63157877876946881815570249290,
              -0.88990336451333310820698117400e-1, 0.18148505520854727256656404962e+2,
              -0.91946323924783554000451984436e+1, -0.44360363875948939664310572000e+1]
D[1, DENSE_STAGES] = [0.10427508642579134603413151009e+2, 0.24228349177525818288430175319e+3,
              0.16520045171727028198505394887e+3, -0.37454675472269020279518312152e+3,
              -0.22113666853125306036270938578e+2, 0.77334326684722638389603898808e+1,
              -0.30674084731089398182061213626e+2, -0.93321305264302278729567221706e+1,
              0.15697238121770843886131091075e+2, -0.31139403219565177677282850411e+2,
              -0.93529243588444783865713862664e+1, 0.35816841486394083752465898540e+2]
D[2, DENSE_STAGES] = [0.19985053242002433820987653617e+2, -0.38703730874935176555105901742e+3,
              -0.18917813819516756882830838328e+3, 0.52780815920542364900561016686e+3,
              -0.11573902539959630126141871134e+2, 0.68812326946963000169666922661e+1,
              -0.10006050966910838403183860980e+1, 0.77771377980534432092869265740,
              -0.27782057523535084065932004339e+1, -0.60196695231264120758267380846e+2,
              0.84320405506677161018159903784e+2, 0.11992291136182789328035130030e+2]
D[3, DENSE_STAGES] = [-0.25693933462703749003312586129e+2, -0.15418974869023643374053993627e+3,
              -0.23152937917604549567536039109e+3, 0.35763911791061412378285349910e+3,
              0.93405324183624310003907691704e+2, -0.37458323136451633156875139351e+2,
              0.10409964950896230045147246184e+3, 0.29840293426660503123344363579e+2,
              -0.43533456590011143754432175058e+2, 0.96324553959188282948394950600e+2,
              -0.39177261675615439165231486172e+2, -0.14972683625798562581422125276e+3]

# the outcome codes of integrate (counts[STATUS])
SUCCESS = 0
STEP_TOO_SMALL = 1
# counts: what integrate did
EVALUATIONS, ACCEPTED, REJECTED, DENSE_STEPS, STATUS = range(5)


@jit
def chain_rhs(y, A_hertz, d0, damping, load, invm, f, dy):
    """dy = F(y) (m/s, m/s^2) for the chain's state y = [u, v] (module doc); f (size nb + 1)
    holds the dynamic forces (N), f[0] = 0 and f[nb] = -load[nb] set by the caller."""
    nb = invm.shape[0]
    contact_forces(y[:nb], y[nb:], A_hertz, d0, damping, HERTZ, load, f)
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
def starting_step(y, k, t_end, rtol, atol, A_hertz, d0, damping, load, invm, f, work, scale):
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
    chain_rhs(work, A_hertz, d0, damping, load, invm, f, k[1])
    for i in range(n):
        work[i] = k[1, i] - k[0, i]
    n2 = rms(work, scale) / h0
    if n1 <= 1e-15 and n2 <= 1e-15:
        h1 = max(1e-6, h0 * 1e-3)
    else:
        h1 = (0.01 / max(n1, n2)) ** (1.0 / 8.0)
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
def integrate(y, t_end, rtol, atol, A_hertz, d0, damping, load, invm, slot, sample_interval,
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
    chain_rhs(y, A_hertz, d0, damping, load, invm, f, k[0])
    h = starting_step(y, k, t_end, rtol, atol, A_hertz, d0, damping, load, invm, f, work[0], work[1])
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
            chain_rhs(work[0], A_hertz, d0, damping, load, invm, f, k[s])
        stage_argument(y, k, N_STAGES, h, y_new)
        counts[EVALUATIONS] += N_STAGES - 1
        err = error_norm(y, y_new, k, h, rtol, atol, work[0], work[1])
        fac11 = err ** 0.125
        if err <= 1.0:
            fac = max(1.0 / FAC2, min(1.0 / FAC1, fac11 / SAFETY))
            h_new = h / fac
            chain_rhs(y_new, A_hertz, d0, damping, load, invm, f, k[N_STAGES])
            counts[EVALUATIONS] += 1
            counts[ACCEPTED] += 1
            t_new = t_end if last else t + h
            if j_out < n_out and (last or j_out * sample_interval <= t_new):
                for s in range(N_STAGES + 1, N_STAGES_EXTENDED):
                    stage_argument(y, k, s, h, work[0])
                    chain_rhs(work[0], A_hertz, d0, damping, load, invm, f, k[s])
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
