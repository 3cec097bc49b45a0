"""The analysis of one pulse pair, compiled (numba): a channel's pulses, the leading pulse's
parabola and widths, and their delay (the cross-correlation: correlation.py; a channel's
baseline, noise and force: baseline.py). The pipeline (instruments/analysis/pipeline.py)
calls these for one record, and the batched analysis (instruments/analysis/batch.py) for
every shot of a study in one compiled loop: the same code, so the same bits.

candidates, refine and correlation.xcorr_lag, each called from one place, are inlined there: numba
links a callee's machine code into each caller's module and optimises it again, so a
level of calls of its own cost their subtree's compile once more (1.3 s CPU of a shot's
analysis).
"""
import math

import numpy as np

from numerics.jit import jit

from .correlation import xcorr_lag
from .crossings import level_bracket
from .parabola import parabola
from .peaks import local_maxima, thin_by_distance, widths_at
from .prominence import prominent
from .select import kept, largest, stable_order, taken

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
