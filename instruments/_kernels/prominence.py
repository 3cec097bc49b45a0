"""Topographic prominence bases of every sample in one pass (numba).

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

from instruments.jit import jit


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
