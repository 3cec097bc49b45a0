"""The oscilloscope's 8-bit converter (numba): one pass from volts to codes."""
import numpy as np

from instruments.jit import jit


@jit
def quantise(v, offset, ymult, yoff, sd, noise, lo, hi):
    """Codes round((v - offset) / ymult + yoff [+ sd * noise]) clipped to [lo, hi] (int8),
    and whether any was clipped. ``noise``: standard normal draws, one per sample, or an
    empty array for none. The same operations, in the same order, as numpy's
    clip(rint((v - offset) / ymult + yoff + sd * noise), lo, hi).astype(int8), in one pass."""
    n = v.shape[0]
    codes = np.empty(n, np.int8)
    noisy = noise.shape[0] > 0
    clipped = False
    for k in range(n):
        c = (v[k] - offset) / ymult + yoff
        if noisy:
            c = c + sd * noise[k]
        c = np.rint(c)
        if c > hi:
            c = hi
            clipped = True
        elif c < lo:
            c = lo
            clipped = True
        codes[k] = np.int8(c)
    return codes, clipped
