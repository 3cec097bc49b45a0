"""Topographic prominence of every sample in one pass (numba).

For a peak p, scipy.signal.peak_prominences (wlen None) scans left from p while the
signal stays <= x[p], keeping the lowest sample met (the first one, counting outward, on
ties) as the left base, likewise to the right, and returns x[p] - max(left min, right min).
The scan is O(n) per peak, so noisy records with many candidate maxima cost O(n k). The
same bases follow in O(n) from a stack of the samples that are still "higher than
everything after them": scanning left to right, the samples popped when x[i] arrives are
exactly those the leftward scan from i would cross, and each carries the minimum of the
stretch it covers. Running the scan on the reversed signal gives the right bases.
"""
import numpy as np
from numba import njit


@njit(cache=True, fastmath=False)
def _left_bases(x, base):
    """base[i]: scipy's left base of sample i (the closest lowest sample before the first
    higher one)."""
    n = x.shape[0]
    stack = np.empty(n, np.int64)   # indices, values strictly decreasing from the bottom
    seg = np.empty(n, np.int64)     # argmin of the stretch each stack entry covers
    top = 0
    for i in range(n):
        arg = i
        while top > 0 and x[stack[top - 1]] <= x[i]:
            top -= 1
            k = seg[top]
            if x[k] < x[arg]:      # strictly lower: on ties the sample closer to i stays
                arg = k
        stack[top] = i
        seg[top] = arg
        top += 1
        base[i] = arg


@njit(cache=True, fastmath=False)
def prominence_bases(x):
    """(left bases, right bases) of every sample of x, as scipy.signal.peak_prominences
    finds them for a peak there (int64 indices)."""
    n = x.shape[0]
    left = np.empty(n, np.int64)
    mirrored = np.empty(n, np.int64)
    _left_bases(x, left)
    _left_bases(x[::-1].copy(), mirrored)
    right = np.empty(n, np.int64)
    for i in range(n):
        right[i] = n - 1 - mirrored[n - 1 - i]
    return left, right
