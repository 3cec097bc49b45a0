"""numpy's array selections and searches as plain loops (numba): ``a[keep]`` for a boolean
mask, ``a[idx]`` for an index array, a strided slice's copy, np.max, np.argmax,
np.searchsorted and a stable argsort. numba lowers each selection written with numpy's
indexing into its caller, a large block of code for every one (candidates' six took 1.9 s
of its compile), and compiles its own np.max, np.argmax and np.searchsorted in every
process for every caller's types (about 0.6 s of a cold shot), never cached; as calls of
these, each element type compiles once. The same elements, in the same order, numpy's
results (NaN included)."""
import numpy as np

from numerics.jit import jit


@jit
def kept(a, keep):
    """a[keep]: the elements of the 1-D array ``a`` where the boolean ``keep`` (same length)
    is True, in order."""
    n = 0
    for k in range(keep.shape[0]):
        n += 1 if keep[k] else 0
    out = np.empty(n, a.dtype)
    m = 0
    for k in range(keep.shape[0]):
        if keep[k]:
            out[m] = a[k]
            m += 1
    return out


@jit
def taken(a, idx):
    """a[idx]: the elements of the 1-D array ``a`` at the indices ``idx`` (each in
    0 .. len(a) - 1), in the order of idx."""
    out = np.empty(idx.shape[0], a.dtype)
    for k in range(idx.shape[0]):
        out[k] = a[idx[k]]
    return out


@jit
def strided(a, first, stop, step):
    """np.ascontiguousarray(a[first:stop:step]) of a 1-D array, 0 <= first <= stop <= len(a),
    step >= 1: every step-th element from first, before stop, in a new array (numba's
    ascontiguousarray of a strided view compiled for 0.17 s)."""
    out = np.empty((stop - first + step - 1) // step, a.dtype)
    for k in range(out.shape[0]):
        out[k] = a[first + k * step]
    return out


@jit
def stable_order(values):
    """np.argsort(values, kind="stable") of 1-D float ``values`` without NaN (a pulse's
    candidate heights: local maxima above a floor never are): the indices that sort them
    ascending, equal values in their order. A bottom-up merge sort; numba's own stable
    argsort compiles its generic comparisons (complex numbers, NaN) for about 1 s."""
    n = values.shape[0]
    order = np.empty(n, np.int64)
    for k in range(n):
        order[k] = k
    merged = np.empty(n, np.int64)
    width = 1
    while width < n:
        for lo in range(0, n, 2 * width):
            mid, hi = min(lo + width, n), min(lo + 2 * width, n)
            i, j = lo, mid
            for k in range(lo, hi):
                if j < hi and (i >= mid or values[order[j]] < values[order[i]]):  # the left run first on ties
                    merged[k] = order[j]
                    j += 1
                else:
                    merged[k] = order[i]
                    i += 1
        order, merged = merged, order
        width *= 2
    return order


@jit
def largest(a):
    """np.max(a) of a non-empty 1-D float array as numba's own computes it: the first of the
    largest elements (of 0.0 and -0.0, the first), the first nan where any is nan."""
    top = a[0]
    for k in range(a.shape[0]):
        if a[k] != a[k]:
            return a[k]
        if a[k] > top:
            top = a[k]
    return top


@jit
def first_largest(a):
    """np.argmax(a) of a non-empty 1-D float array: the first largest element's index, the
    first nan's where any is nan."""
    best = 0
    for k in range(1, a.shape[0]):
        if a[best] == a[best] and (a[k] > a[best] or a[k] != a[k]):
            best = k
    return best


@jit
def left_index(a, value):
    """np.searchsorted(a, value) of an ascending 1-D float array: the first index k with
    a[k] >= value (len(a) where none), a nan sorted after every number as numpy sorts it."""
    lo, hi = 0, a.shape[0]
    while lo < hi:
        mid = (lo + hi) // 2
        if a[mid] < value or (value != value and a[mid] == a[mid]):
            lo = mid + 1
        else:
            hi = mid
    return lo
