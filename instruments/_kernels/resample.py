"""Linear interpolation of a uniformly sampled signal (numba)."""
import math

import numpy as np

from instruments.jit import jit


@jit
def at_positions(f, pos):
    """f (samples 0..n-1) read at fractional sample positions ``pos`` by linear
    interpolation, the ends held: np.interp(pos, np.arange(n), f), operation for
    operation, without its binary search."""
    n = f.shape[0]
    out = np.empty(pos.shape[0])
    for i in range(pos.shape[0]):
        p = pos[i]
        if math.isnan(p):
            out[i] = p
        elif p < 0.0:
            out[i] = f[0]
        elif p >= n - 1:
            out[i] = f[n - 1]
        else:
            j = math.floor(p)
            if p == j:
                out[i] = f[j]
            else:
                out[i] = (f[j + 1] - f[j]) * (p - j) + f[j]
    return out
