"""What this machine allows (numba): the throughput of vectorised square roots and the
memory bandwidth of a streaming loop, the two bounds of the chain kernel's cost."""
import math
import statistics
import time

import numpy as np

from numerics.jit import jit


@jit
def _sqrt_sweeps(x, out, reps):
    for _ in range(reps):
        for i in range(x.shape[0]):
            out[i] = math.sqrt(x[i])
        x[0] += out[1] * 1e-300  # keep the sweeps from being folded into one


@jit
def _triad(a, b, c, s, reps):
    for _ in range(reps):
        for i in range(a.shape[0]):
            a[i] = b[i] + s * c[i]


def sqrt_ns(n: int = 1024, reps: int = 100_000) -> float:
    """ns per square root in a vectorised loop over n cache-resident doubles (median of 5)."""
    x, out = np.linspace(1.0, 2.0, n), np.empty(n)
    _sqrt_sweeps(x, out, 1)
    times = []
    for _ in range(5):
        t0 = time.process_time()
        _sqrt_sweeps(x, out, reps)
        times.append((time.process_time() - t0) / (reps * n) * 1e9)
    return statistics.median(times)


def triad_bandwidth(n: int = 16_000_000, reps: int = 5) -> float:
    """GB/s of the STREAM triad a = b + s c over arrays far beyond the caches (128 MB
    each), counting 32 bytes per element (two reads, a write and its read for ownership)."""
    a, b, c = np.zeros(n), np.ones(n), np.ones(n)
    _triad(a, b, c, 0.5, 1)
    times = []
    for _ in range(3):
        t0 = time.perf_counter()
        _triad(a, b, c, 0.5, reps)
        times.append(time.perf_counter() - t0)
    return 32.0 * n * reps / statistics.median(times) / 1e9
