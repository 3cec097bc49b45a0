"""The oscilloscope's 8-bit converter (numba): one pass from volts to codes."""
import numpy as np

from instruments.jit import jit


@jit(inline="always")
def code(v, offset, ymult, yoff, noisy, noise):
    """One sample's code before clipping: rint((v - offset) / ymult + yoff [+ noise])."""
    c = (v - offset) / ymult + yoff
    if noisy:
        c = c + noise
    return np.rint(c)


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
        c = code(v[k], offset, ymult, yoff, noisy, sd * noise[k] if noisy else 0.0)
        clipped |= c > hi or c < lo
        codes[k] = np.int8(min(max(c, lo), hi))
    return codes, clipped
