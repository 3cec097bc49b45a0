"""A channel's baseline (numba): its pre-trigger mean, its noise (the median absolute
deviation of the pre-trigger samples) and its force conditioned from the volts, which the
pipeline (instruments/analysis/condition.py) and the batched analysis (batch_analysis.py)
both take."""
import math

import numpy as np

from instruments._kernels.filters import undo_highpass_into
from numerics.jit import jit

MIN_BASELINE = 16  # pre-trigger samples needed to measure the noise (the MAD to about 1/3)
MAD_TO_SD = 1.4826  # the standard deviation of Gaussian noise over its median absolute deviation


@jit
def baseline_mean(y, n_pre):
    """Mean of the first max(n_pre, 10) samples of y (the pre-trigger baseline)."""
    n = min(max(n_pre, 10), y.shape[0])
    s = 0.0
    for k in range(n):
        s += y[k]
    return s / n if n else math.nan


@jit
def kth_smallest(x, k):
    """The k-th smallest value of x (0-based; x unchanged, no nan): quickselect on the
    median of three, each pass copying the values below and above its pivot into two
    buffers without a branch (noise's comparisons are a coin toss for a branch predictor:
    a third of the time of swapping in place)."""
    n = x.shape[0]
    a = x.copy()
    below = np.empty(n)
    above = np.empty(n)
    while True:
        first, middle, last = a[0], a[n // 2], a[n - 1]
        pivot = max(min(first, last), min(max(first, last), middle))
        n_below = 0
        n_above = 0
        for i in range(n):
            v = a[i]
            below[n_below] = v
            n_below += v < pivot
            above[n_above] = v
            n_above += v > pivot
        if k < n_below:
            a, below = below, a
            n = n_below
        elif k >= n - n_above:
            k -= n - n_above
            a, above = above, a
            n = n_above
        else:
            return pivot


@jit
def median(x):
    """The median of x (numpy's: the middle value, or the mean of the two middle ones; nan
    where x is empty or holds a nan)."""
    n = x.shape[0]
    if n == 0:
        return math.nan
    for v in x:
        if math.isnan(v):
            return math.nan
    k = n // 2
    upper = kth_smallest(x, k)
    if n % 2:
        return upper
    below, lower = 0, -np.inf  # the (k - 1)-th: upper again unless k values lie below it
    for v in x:  # without a branch: noise is below or not at random
        is_below = v < upper
        below += is_below
        lower = max(lower, v if is_below else -np.inf)
    return ((upper if below < k else lower) + upper) / 2.0


@jit
def noise_level(y, n_pre, step):
    """1.4826 x the median absolute deviation of the first n_pre samples of y, never below
    step / sqrt(12); nan with fewer than MIN_BASELINE samples (analysis.noise_level)."""
    if n_pre < MIN_BASELINE:
        return math.nan
    pre = y[:n_pre]
    centre = median(pre)
    mad = MAD_TO_SD * median(np.abs(pre - centre))
    return max(mad, abs(step) / math.sqrt(12.0))


@jit
def conditioned(volts, n_pre, h, tau, sensitivity):
    """Dynamic force (N) of a channel: volts less their pre-trigger mean, the RC high-pass
    of time constant tau (s; 0: none) undone, over the sensitivity (V/N)."""
    out = np.empty(volts.shape[0])
    undo_highpass_into(volts, baseline_mean(volts, n_pre), h, tau, sensitivity, out)
    return out
