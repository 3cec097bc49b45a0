"""The analysis of one pulse pair, compiled (numba): a channel's pulses, the leading pulse's
parabola and widths, the cross-correlation delay (a channel's baseline, noise and force:
baseline.py). The
pipeline (instruments/analysis/pipeline.py) calls these for one record, and the batched analysis
(instruments/analysis/batch.py) for every shot of a study in one compiled loop: the same code, so
the same bits.

candidates, refine and xcorr_lag, each called from one place, are inlined there: numba
links a callee's machine code into each caller's module and optimises it again, so a
level of calls of its own cost their subtree's compile once more (1.3 s CPU of a shot's
analysis).
"""
import math

import numpy as np

from numerics.jit import jit

from .crossings import level_bracket
from .parabola import parabola
from .peaks import local_maxima, thin_by_distance, widths_at
from .prominence import prominent
from .select import first_largest, kept, largest, left_index, stable_order, strided, taken

# the layout of leading_pair's answer
OK, SAME_RECORD, NO_PULSE, SWAPPED = 0, 1, 2, 3
STATUS, LAG = 0, 15
PEAK, FOUND, TIME, AMPLITUDE, FWHM, BASE_WIDTH, RISE = range(7)
ROLE = 7  # fields of each role; role r's field x is at 1 + ROLE r + x
ANSWER = 16


@jit
def index_of(r, field):
    """Index in leading_pair's answer of ``field`` of role r (0: upper gauge, 1: lower)."""
    return 1 + ROLE * r + field


@jit(inline="always")
def first_peak(f):
    """Index of the first local maximum of f - f[0] above half its peak (-1: f never rises
    above f[0]): the sample where the climb from the first one above half stops. Called
    from first_peaks alone, inlined there (a library of its own is compiled, linked and
    optimised once more)."""
    top = 0.0
    for k in range(f.shape[0]):
        top = max(top, f[k] - f[0])
    if top <= 0.0:
        return -1
    i = 0
    while not f[i] - f[0] > 0.5 * top:
        i += 1
    while i + 1 < f.shape[0] and not (f[i + 1] - f[0] < f[i] - f[0]):
        i += 1
    return i


@jit(nogil=True)
def first_peaks(lo, hi, f, rows, out):
    """out[s, k] = first_peak(f[s, rows[k]]) for shots s in lo..hi-1 of f (shots, rows,
    samples): the first crests of many shots' signals, a range of shots per thread."""
    for s in range(lo, hi):
        for k in range(rows.shape[0]):
            out[s, k] = first_peak(f[s, rows[k]])


@jit(inline="always")
def candidates(f, height, min_prominence, spacing, min_width):
    """Indices of f's pulses by find_peaks' rules, in time order: local maxima at least
    ``height`` high, thinned to ``spacing`` samples from the highest down (equal heights:
    the later first), with at least ``min_prominence`` of prominence and ``min_width``
    samples of width at half prominence. Nothing if f never rises above 0."""
    if f.shape[0] == 0 or largest(f) <= 0.0:
        return np.empty(0, np.int64)
    idx = local_maxima(f, height)
    if spacing > 1 and idx.shape[0]:
        idx = kept(idx, thin_by_distance(idx, stable_order(taken(f, idx)), float(spacing)))
    idx, prominence, left, right = prominent(f, idx, min_prominence, height)
    if min_width > 0.0 and idx.shape[0]:
        widths = widths_at(f, idx, 0.5, prominence, left, right)
        wide = np.empty(widths.shape[0], np.bool_)
        for k in range(widths.shape[0]):
            wide[k] = widths[k] >= min_width
        idx = kept(idx, wide)
    return idx


@jit
def _vertex(t, f, i, top):
    """Time and height of the least-squares parabola through the contiguous samples
    within ``top`` of f[i]; the sample itself where no parabola opens downwards there."""
    level = f[i] * (1.0 - top)
    lo, hi = i, i
    while lo > 0 and f[lo - 1] >= level:
        lo -= 1
    while hi < f.shape[0] - 1 and f[hi + 1] >= level:
        hi += 1
    lo, hi = min(lo, i - 1), max(hi, i + 1)
    if lo < 0 or hi >= f.shape[0]:
        return t[i], f[i]
    x = np.empty(hi - lo + 1)  # the samples' offsets from i
    for k in range(x.shape[0]):
        x[k] = lo - i + k
    a, b, c = parabola(x, f[lo:hi + 1])
    if not a < 0.0:
        return t[i], f[i]
    xv = -b / (2.0 * a)
    if not x[0] <= xv <= x[-1]:
        return t[i], f[i]
    return t[i] + xv * (t[1] - t[0]), c - b * b / (4.0 * a)


@jit
def crossings(t, f, i, level):
    """Times (s) where f crosses ``level`` before and after sample i (linear; nan if never)."""
    left, right = level_bracket(f, i, level)
    tl = math.nan if left < 0 else t[left] + (level - f[left]) / (f[left + 1] - f[left]) * (t[left + 1] - t[left])
    tr = math.nan if right < 0 else t[right - 1] + (f[right - 1] - level) / (f[right - 1] - f[right]) * (
        t[right] - t[right - 1])
    return tl, tr


@jit(inline="always")
def refine(t, f, i, top):
    """(time, amplitude, FWHM, 1% width, rise from 1%) of the pulse at sample i."""
    time, amp = _vertex(t, f, i, top)
    h0, h1 = crossings(t, f, i, 0.5 * amp)
    b0, b1 = crossings(t, f, i, 0.01 * amp)
    return time, amp, h1 - h0, b1 - b0, time - b0


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
        bound = np.empty(K)
        for k in range(K):
            bound[k] = math.sqrt(sa) * math.sqrt(max(run[k + m] - run[k], 0.0) + BOUND_SLACK * total) * (
                1.0 + BOUND_SLACK)
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


@jit
def _leading(t, f, sigma, rules, r, out):
    """Role r's leading pulse into out (leading_pair's layout); True where found."""
    height_frac, prominence_frac, top, lead, snr, distance, width = rules
    h = t[1] - t[0]
    peak = largest(f) if f.shape[0] else 0.0
    floor = height_frac * peak if math.isnan(sigma) else max(height_frac * peak, snr * sigma)
    out[index_of(r, PEAK)] = peak
    idx = candidates(f, floor, prominence_frac * peak, int(np.rint(max(distance, 0.5 * width) / h)), width / h)
    out[index_of(r, FOUND)] = 0.0
    if idx.shape[0] == 0:
        return False
    big = largest(taken(f, idx))
    first = idx[0]
    for i in idx:
        if f[i] >= lead * big:
            first = i
            break
    i = int(np.rint((t[first] - t[0]) / (t[1] - t[0])))
    time, amp, fwhm, base, rise = refine(t, f, i, top)
    out[index_of(r, FOUND)] = 1.0
    out[index_of(r, TIME)], out[index_of(r, AMPLITUDE)], out[index_of(r, FWHM)] = time, amp, fwhm
    out[index_of(r, BASE_WIDTH)], out[index_of(r, RISE)] = base, rise
    return True


@jit
def _same(a, b):
    """np.array_equal(a, b) of 1-D float arrays (nan equal to nothing)."""
    if a.shape[0] != b.shape[0]:
        return False
    for k in range(a.shape[0]):  # noqa: SIM110 - numba compiles no generator for all()
        if a[k] != b[k]:
            return False
    return True


@jit
def leading_pair(t, up, low, sigma_up, sigma_low, rules, out):
    """The leading pulses of the upper and lower gauges' forces (time t, s) and their delay
    by cross-correlation, into out (ANSWER floats: STATUS, each role's PEAK, FOUND, TIME,
    AMPLITUDE, FWHM, BASE_WIDTH, RISE at index_of(r, field), LAG). sigma: each channel's noise
    (nan: unknown, no SNR rule). rules: PeakRules' (height, prominence, top, lead, snr,
    distance, width) as a tuple of floats. STATUS: OK, SAME_RECORD,
    NO_PULSE (FOUND says which), SWAPPED (the lower pulse first)."""
    out[:] = math.nan
    if _same(up, low):
        out[STATUS] = SAME_RECORD
        return
    found_up = _leading(t, up, sigma_up, rules, 0, out)
    found_low = _leading(t, low, sigma_low, rules, 1, out)
    if not (found_up and found_low):
        out[STATUS] = NO_PULSE
        return
    if out[index_of(1, TIME)] <= out[index_of(0, TIME)]:
        out[STATUS] = SWAPPED
        return
    out[STATUS] = OK
    out[LAG] = xcorr_lag(t, up, out[index_of(0, TIME)], out[index_of(0, FWHM)], low, out[index_of(1, TIME)])
