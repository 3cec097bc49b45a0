"""The oscilloscope's 8-bit converter (numba): one pass from volts to codes."""
import numpy as np

from numerics.jit import jit


@jit(inline="always")
def code(v, offset, ymult, yoff, noisy, noise):
    """One sample's code before clipping: rint((v - offset) / ymult + yoff [+ noise])."""
    c = (v - offset) / ymult + yoff
    if noisy:
        c = c + noise
    return np.rint(c)


@jit
def quantise(v, offset, ymult, yoff, sd, noise, lo, hi, codes):
    """Codes round((v - offset) / ymult + yoff [+ sd * noise]) clipped to [lo, hi] into
    ``codes`` (int8, v's length); returns whether any was clipped. ``noise``: standard
    normal draws, one per sample, or an empty array for none. The same operations, in the
    same order, as numpy's clip(rint((v - offset) / ymult + yoff + sd * noise), lo,
    hi).astype(int8), in one pass that vectorises (a loop for each case, the settings held
    in locals)."""
    clipped = False
    if noise.shape[0] > 0:
        for k in range(v.shape[0]):
            c = code(v[k], offset, ymult, yoff, True, sd * noise[k])
            clipped |= c > hi or c < lo
            codes[k] = np.int8(min(max(c, lo), hi))
    else:
        for k in range(v.shape[0]):
            c = code(v[k], offset, ymult, yoff, False, 0.0)
            clipped |= c > hi or c < lo
            codes[k] = np.int8(min(max(c, lo), hi))
    return clipped
