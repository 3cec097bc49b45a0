"""Linear interpolation of a uniformly sampled signal (numba)."""
import math

import numpy as np

from numerics.jit import jit


@jit(inline="always")
def read_at(f, p):
    """f (samples 0..n-1) at the fractional position p >= 0 or not (not nan), linearly
    interpolated, the ends held: np.interp's operations."""
    n = f.shape[0]
    if p < 0.0:
        return f[0]
    if p >= n - 1:
        return f[n - 1]
    j = int(p)  # p >= 0: the floor
    if p == j:
        return f[j]
    return (f[j + 1] - f[j]) * (p - j) + f[j]


@jit
def at_positions(f, pos):
    """f (samples 0..n-1) read at fractional sample positions ``pos`` by linear
    interpolation, the ends held: np.interp(pos, np.arange(n), f), operation for
    operation, without its binary search."""
    out = np.empty(pos.shape[0])
    for i in range(pos.shape[0]):
        p = pos[i]
        out[i] = p if math.isnan(p) else read_at(f, p)
    return out
