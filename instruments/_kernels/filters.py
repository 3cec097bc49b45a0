"""One-pole recursive filter (numba) for the analog front ends (instruments/frontend.py)."""
import numpy as np

from instruments.jit import jit


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
    n = y.shape[0]
    x = np.empty(n)
    acc = 0.0
    if n:
        x[0] = y[0] + acc / tau
    for k in range(1, n):
        acc = acc + h * (y[k] + y[k - 1]) / 2.0
        x[k] = y[k] + acc / tau
    return x
