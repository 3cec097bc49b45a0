"""One-pole recursive filter (numba) for the analog front ends (instruments/devices/frontend.py)."""
import numpy as np

from numerics.jit import jit


@jit(inline="always")
def pole_step(z, u, b0, b1, a1):
    """One sample of a one-pole filter in direct form II transposed (scipy.signal.lfilter's
    operations): input u, state z -> (output y = z + b0 u, next state u b1 - y a1)."""
    y = z + b0 * u
    return y, u * b1 - y * a1


@jit
def one_pole(x, b0, b1, a1, level, restore):
    """y[n] = b0 u[n] + b1 u[n-1] - a1 y[n-1], u = x - level, from rest; plus level again
    when ``restore``. Operation for operation what scipy.signal.lfilter([b0, b1], [1, a1],
    x - level) computes (direct form II transposed), in one pass over x."""
    n = x.shape[0]
    y = np.empty(n)
    z = 0.0
    for k in range(n):
        yk, z = pole_step(z, x[k] - level, b0, b1, a1)
        y[k] = yk + level if restore else yk
    return y


@jit
def undo_highpass(y, h, tau):
    """x[n] = y[n] + (1/tau) sum_{k<=n} h (y[k] + y[k-1]) / 2 (trapezoid rule): the input of
    a one-pole RC high-pass from its output. The same operations as
    y + scipy.integrate.cumulative_trapezoid(y, dx=h, initial=0) / tau, in one pass."""
    x = np.empty(y.shape[0])
    undo_highpass_into(y, 0.0, h, tau, 1.0, x)  # less 0, over 1: the same numbers
    return x


@jit
def undo_highpass_into(y, level, h, tau, scale, out):
    """out[n] = x[n] / scale, x undo_highpass's input of the RC high-pass (tau s; 0: none,
    x = y - level) whose output is y - level, with undo_highpass's operations in its order.
    out may be y itself. The integral's running sum is a chain of additions; the two
    divisions of each sample, which do not wait on it, run in a second pass that
    vectorises (a scalar division's throughput had bounded the loop)."""
    n = y.shape[0]
    if not tau > 0.0:
        for k in range(n):
            out[k] = (y[k] - level) / scale
        return
    shifted, acc = np.empty(n), np.empty(n)  # y - level, and the running sum before sample k's division by tau
    total = 0.0
    for k in range(n):
        shifted[k] = y[k] - level
        if k:
            total = total + h * (shifted[k] + shifted[k - 1]) / 2.0
        acc[k] = total
    for k in range(n):  # reads neither y nor out: a vector loop where out is y
        out[k] = (shifted[k] + acc[k] / tau) / scale
