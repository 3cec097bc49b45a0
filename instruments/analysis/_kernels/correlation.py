"""The delay of pulse b after pulse a by cross-correlation, compiled (numba): the
correlation's sums (``correlate``), its peak from the lags that can hold it
(``correlation_peak``) and the delay with a parabola through that peak (``xcorr_lag``,
inlined in pulses.leading_pair, which the pipeline and the batched analysis both run)."""
import math

import numpy as np

from numerics.jit import jit

from .select import first_largest, left_index, strided


@jit
def correlate(a, b, c):
    """c[k] += sum_j a[j] b[j + k] for every lag k < c.shape[0], each sum taken over j in
    order. The loop over lags vectorises; eight j at a time keep c in registers eight times
    as long and add in the same order, so the same bits."""
    K = c.shape[0]
    j = 0
    while j + 8 <= a.shape[0]:
        a0, a1, a2, a3, a4, a5, a6, a7 = a[j], a[j + 1], a[j + 2], a[j + 3], a[j + 4], a[j + 5], a[j + 6], a[j + 7]
        w = b[j:j + K + 7]
        for k in range(K):
            c[k] = (((((((c[k] + w[k] * a0) + w[k + 1] * a1) + w[k + 2] * a2) + w[k + 3] * a3) + w[k + 4] * a4)
                     + w[k + 5] * a5) + w[k + 6] * a6) + w[k + 7] * a7
        j += 8
    while j + 4 <= a.shape[0]:
        a0, a1, a2, a3 = a[j], a[j + 1], a[j + 2], a[j + 3]
        w = b[j:j + K + 3]
        for k in range(K):
            c[k] = (((c[k] + w[k] * a0) + w[k + 1] * a1) + w[k + 2] * a2) + w[k + 3] * a3
        j += 4
    while j < a.shape[0]:
        w = b[j:j + K]
        for k in range(K):
            c[k] += w[k] * a[j]
        j += 1


XCORR_POINTS = 4096
"""The most samples of pulse a that the correlation's first search takes: a record sampled
finer (a window of m > XCORR_POINTS samples) is searched every s = m // XCORR_POINTS samples,
then at every sample within s + 1 of that search's peak, so its cost is about
m^2 / s^2 + 2 s m products instead of m^2 (a 0.2 ns record of a 40 us pulse: 0.4 M samples,
22 s -> 0.1 s). The lag is the full correlation's where it has one maximum within s
samples of the coarse one (a smooth pulse: its peak is many thousand samples wide); a
window of at most XCORR_POINTS samples takes the full correlation, as before."""


@jit(inline="always")
def parabola_shift(c, k):
    """The offset (samples, within +-1/2 where c is concave) of the vertex of the parabola
    through c[k - 1], c[k], c[k + 1]; 0 at an end of c or where they lie on a line."""
    if 0 < k < c.shape[0] - 1:
        den = c[k - 1] - 2.0 * c[k] + c[k + 1]
        return 0.5 * (c[k - 1] - c[k + 1]) / den if den != 0.0 else 0.0
    return 0.0


BOUND_SLACK = 1e-9
"""correlation_peak's margin on its Cauchy-Schwarz bounds (relative, and of the whole
window's sum of squares inside each lag's): far above the rounding of its sums (at most
about n 2^-53 of them, n < 10^4 samples) and far below what the bounds prune."""
SAFE_SUMS = (1e-200, 1e200)  # the sums of squares the bounds take: beyond them, underflow and overflow


@jit
def correlation_peak(a, b):
    """(k, parabola_shift(c, k)) of the first largest c[k] = sum_j a[j] b[j + k] (correlate's
    sums, k = 0 .. len(b) - len(a)), computed only at the lags that can hold it: by
    Cauchy-Schwarz, c[k] <= |a| |b[k:k + len(a)]|, so a lag whose bound (with
    BOUND_SLACK's margin) lies below a value c takes at another lag is never the largest.
    The lags from the first to the last whose bounds reach c at the largest bound, and
    their neighbours, are computed as correlate computes every lag: the same bits as the
    full correlation. A pulse's window keeps about a tenth of its lags (ptfe52_magnetic's
    55 of 612); a window with a value that is not finite, or sums of squares outside
    SAFE_SUMS, takes the full correlation. Called, not inlined: inlined in the leading
    pair, it cost that compile about 0.4 s more."""
    m, K = a.shape[0], b.shape[0] - a.shape[0] + 1
    sa = 0.0
    for j in range(m):
        sa += a[j] * a[j]
    run = np.empty(b.shape[0] + 1)  # running sums of b^2
    run[0] = 0.0
    for j in range(b.shape[0]):
        run[j + 1] = run[j] + b[j] * b[j]
    total = run[b.shape[0]]
    lo, hi = 0, K - 1
    if SAFE_SUMS[0] < sa < SAFE_SUMS[1] and SAFE_SUMS[0] < total < SAFE_SUMS[1]:
        norm_a, bound = math.sqrt(sa), np.empty(K)
        for k in range(K):
            bound[k] = norm_a * math.sqrt(max(run[k + m] - run[k], 0.0) + BOUND_SLACK * total) * (1.0 + BOUND_SLACK)
        top = first_largest(bound)
        best = 0.0  # c[top], its sum in correlate's order
        for j in range(m):
            best += a[j] * b[top + j]
        first, last = K, -1  # the lags whose bounds reach best (top among them)
        for k in range(K):
            if bound[k] >= best:
                first, last = min(first, k), max(last, k)
        if first <= last:  # not so where best is nan
            lo, hi = max(0, first - 1), min(K - 1, last + 1)  # and their neighbours, for the parabola
    c = np.zeros(hi - lo + 1)
    correlate(a, b[lo:hi + m], c)
    k = first_largest(c)
    return lo + k, parabola_shift(c, k)


@jit(inline="always")
def xcorr_lag(t, fa, time_a, fwhm_a, fb, time_b):
    """Delay (s) of pulse b after pulse a: a's window one FWHM either side of its maximum,
    searched in b's window twice as wide, a parabola through the correlation peak (a long
    window searched coarsely first: XCORR_POINTS)."""
    h = t[1] - t[0]
    half = fwhm_a
    if not (math.isfinite(half) and half > 0.0):
        return math.nan
    ia0, ia1 = left_index(t, time_a - half), left_index(t, time_a + half)
    ib0, ib1 = left_index(t, time_b - 2.0 * half), left_index(t, time_b + 2.0 * half)
    m, nb = ia1 - ia0, ib1 - ib0
    if m < 3 or nb <= m:
        return math.nan
    s = max(1, m // XCORR_POINTS)
    if s == 1:
        k, shift = correlation_peak(fa[ia0:ia1], fb[ib0:ib1])
        return (ib0 + k + shift - ia0) * h
    a = strided(fa, ia0, ia1, s)
    b = strided(fb, ib0, ib1, s)
    coarse = np.zeros(b.shape[0] - a.shape[0] + 1)
    correlate(a, b, coarse)
    peak = first_largest(coarse) * s
    lo, hi = max(0, peak - s - 1), min(nb - m, peak + s + 1)
    c = np.zeros(hi - lo + 1)
    for k in range(c.shape[0]):
        acc = 0.0
        for j in range(m):
            acc += fa[ia0 + j] * fb[ib0 + lo + k + j]
        c[k] = acc
    k = first_largest(c)
    return (ib0 + lo + k + parabola_shift(c, k) - ia0) * h
