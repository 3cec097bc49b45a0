"""Topographic prominences of pulse candidates (numba): ``prominent`` keeps the peaks that
pass find_peaks' prominence rule, with scipy's prominences and bases, from early-dropping
scans, and falls back on the bases of every sample in one pass (``prominence_bases``)
where the scans grow long.

For a peak p, scipy.signal.peak_prominences (wlen None) scans left from p while the
signal stays <= x[p], keeping the lowest sample met (the first one, counting outward, on
ties) as the left base, likewise to the right, and returns x[p] - max(left min, right min).
The scan is O(n) per peak, so noisy records with many candidate maxima cost O(n k). The
same bases follow in O(n) from a stack of the samples that are still "higher than
everything after them": scanning left to right, the samples popped when x[i] arrives are
exactly those the leftward scan from i would cross, and each carries the minimum of the
stretch it covers. Running the scan on the reversed signal gives the right bases.

Only the bases of samples at or above ``floor`` are wanted (find_peaks' height rule):
a sample below the floor never stops a scan from such a sample, so each run of them enters
the stack as its lowest sample alone (the last of equal lows, the one closest to what
follows), which keeps the noisy baseline of a record out of the stack.
"""
import numpy as np

from numerics.jit import jit

from .select import kept, taken


@jit
def _left_bases(x, floor, base):
    """base[i]: scipy's left base of sample i (the closest lowest sample before the first
    higher one) for x[i] >= floor; -1 for the samples below the floor."""
    n = x.shape[0]
    stack = np.empty(n, np.int64)   # indices, values strictly decreasing from the bottom
    seg = np.empty(n, np.int64)     # argmin of the stretch each stack entry covers
    top = 0
    i = 0
    while i < n:
        pivot = i  # what enters the stack: sample i, or the lowest of a run below the floor
        if x[i] < floor:
            base[i] = -1
            while i + 1 < n and x[i + 1] < floor:
                i += 1
                base[i] = -1
                if x[i] <= x[pivot]:
                    pivot = i
        arg = pivot
        while top > 0 and x[stack[top - 1]] <= x[pivot]:
            top -= 1
            k = seg[top]
            if x[k] < x[arg]:      # strictly lower: on ties the sample closer to i stays
                arg = k
        stack[top] = pivot
        seg[top] = arg
        top += 1
        if x[i] >= floor:
            base[i] = arg
        i += 1


@jit
def prominence_bases(x, floor=-np.inf):
    """(left bases, right bases) of every sample of x at or above ``floor``, as
    scipy.signal.peak_prominences finds them for a peak there (int64 indices; -1 below
    the floor)."""
    n = x.shape[0]
    left = np.empty(n, np.int64)
    mirrored = np.empty(n, np.int64)
    _left_bases(x, floor, left)
    _left_bases(x[::-1].copy(), floor, mirrored)
    right = np.empty(n, np.int64)
    for i in range(n):
        m = mirrored[n - 1 - i]
        right[i] = n - 1 - m if m >= 0 else -1
    return left, right


@jit
def prominent(x, peaks, min_prominence, floor=-np.inf):
    """The peaks of ``peaks`` (indices into x, each at or above ``floor``) whose
    topographic prominence is at least ``min_prominence``, with their prominences and
    scipy's left and right bases (find_peaks' prominence rule, bit for bit).

    Each peak's two scans (scipy's: outward while the signal stays <= the peak, keeping the
    lowest sample met, the first on ties) run in step, and a peak is dropped as soon as one
    finished side has no dip of min_prominence below it: its prominence cannot reach the
    rule. A noise wiggle on a pulse's flank ends in a few samples that way; the few pulses
    that pass cost their two scans. Where the scans together pass more than eight times the
    record's length (a record of many equal pulses, whose scans run from end to end), the
    bases of every sample come from prominence_bases' one pass instead (O(n))."""
    n, k = x.shape[0], peaks.shape[0]
    keep = np.zeros(k, np.bool_)
    prom, left, right = np.empty(k), np.empty(k, np.int64), np.empty(k, np.int64)
    budget = 8 * n + 64
    for j in range(k):
        p = peaks[j]
        top = x[p]
        lo, hi = p - 1, p + 1
        lbase = rbase = p
        lmin = rmin = top
        ldone = rdone = False
        dropped = False
        while not (ldone and rdone):
            budget -= 1
            if not ldone:
                if lo >= 0 and x[lo] <= top:
                    if x[lo] < lmin:
                        lmin, lbase = x[lo], lo
                    lo -= 1
                else:
                    ldone = True
                    dropped = top - lmin < min_prominence
            if not rdone and not dropped:
                if hi < n and x[hi] <= top:
                    if x[hi] < rmin:
                        rmin, rbase = x[hi], hi
                    hi += 1
                else:
                    rdone = True
                    dropped = top - rmin < min_prominence
            if dropped:
                break
        if budget < 0:
            return _prominent_in_one_pass(x, peaks, min_prominence, floor)
        if not dropped:
            prom[j] = top - max(lmin, rmin)
            keep[j] = prom[j] >= min_prominence
            left[j], right[j] = lbase, rbase
    return kept(peaks, keep), kept(prom, keep), kept(left, keep), kept(right, keep)


@jit
def _prominent_in_one_pass(x, peaks, min_prominence, floor):
    """prominent's answer from every sample's bases (prominence_bases)."""
    lb, rb = prominence_bases(x, floor)
    k = peaks.shape[0]
    prom, keep = np.empty(k), np.empty(k, np.bool_)
    for j in range(k):
        prom[j] = x[peaks[j]] - np.maximum(x[lb[peaks[j]]], x[rb[peaks[j]]])
        keep[j] = prom[j] >= min_prominence
    return kept(peaks, keep), kept(prom, keep), kept(taken(lb, peaks), keep), kept(taken(rb, peaks), keep)
