"""Candidate maxima and widths of pulses, the loops of scipy.signal.find_peaks and
peak_widths (numba), so that analysing a record does not load scipy.signal (about 1 s of
import time). Each reproduces scipy's algorithm step for step, in the same arithmetic:
tests/instruments/test_compiled_helpers.py compares them with scipy bit for bit.
"""
import numpy as np

from numerics.jit import jit


@jit
def local_maxima(x, floor=-np.inf):
    """Indices of the local maxima of x at or above ``floor``: samples higher than their
    left neighbour and than the first different sample on their right; a flat top counts
    once, at its middle ((first + last) // 2), as scipy.signal's _local_maxima_1d. The
    floor (find_peaks' height rule) gives the maxima that filtering all of them by it
    gives. A first pass notes, without a branch, every sample at or above the floor that
    rises from its left neighbour and does not fall short of its right one (a noisy
    pulse's rises and falls are a coin toss for the branch predictor); the second walks
    those few, each flat top to its end."""
    n = x.shape[0]
    rising = np.empty(max(n, 2) // 2 + 1, np.int64)  # two such samples are never neighbours
    m = 0
    for i in range(1, n - 1):
        rising[m] = i
        m += (x[i] >= floor) & (x[i - 1] < x[i]) & (x[i + 1] <= x[i])
    out = np.empty(m, np.int64)
    found = 0
    last = n - 1
    for r in range(m):
        i = rising[r]
        ahead = i + 1
        while ahead < last and x[ahead] == x[i]:
            ahead += 1
        if x[ahead] < x[i]:
            out[found] = (i + ahead - 1) // 2
            found += 1
    return out[:found]


@jit
def thin_by_distance(peaks, order, distance):
    """keep[k] for peaks[k]: from the highest peak down (``order``: np.argsort of their
    heights, as scipy computes it), every lower peak closer than ceil(distance) samples to a
    kept one is dropped (scipy.signal's _select_by_peak_distance)."""
    n = peaks.shape[0]
    span = np.ceil(distance)
    keep = np.ones(n, np.bool_)
    for r in range(n - 1, -1, -1):
        j = order[r]
        if not keep[j]:
            continue
        k = j - 1
        while k >= 0 and peaks[j] - peaks[k] < span:
            keep[k] = False
            k -= 1
        k = j + 1
        while k < n and peaks[k] - peaks[j] < span:
            keep[k] = False
            k += 1
    return keep


@jit
def widths_at(x, peaks, rel_height, prominences, left_bases, right_bases):
    """Width (samples) of each peak where it crosses x[peak] - rel_height * prominence,
    interpolated linearly, searched between its bases (scipy.signal's _peak_widths)."""
    out = np.empty(peaks.shape[0])
    for p in range(peaks.shape[0]):
        lo, hi, peak = left_bases[p], right_bases[p], peaks[p]
        height = x[peak] - prominences[p] * rel_height
        i = peak
        while lo < i and height < x[i]:
            i -= 1
        left = float(i)
        if x[i] < height:
            left += (height - x[i]) / (x[i + 1] - x[i])
        i = peak
        while i < hi and height < x[i]:
            i += 1
        right = float(i)
        if x[i] < height:
            right -= (height - x[i]) / (x[i - 1] - x[i])
        out[p] = right - left
    return out
