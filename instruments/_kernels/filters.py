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
    x = y - level) whose output is y - level: one pass, with undo_highpass's operations in
    its order. out may be y itself."""
    acc = 0.0
    before = 0.0
    for k in range(y.shape[0]):
        yk = y[k] - level
        if tau > 0.0:
            if k:
                acc = acc + h * (yk + before) / 2.0
            out[k] = (yk + acc / tau) / scale
        else:
            out[k] = yk / scale
        before = yk
