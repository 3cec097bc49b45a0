"""Analog signal conditioning as pure functions of sampled signals (uniform step h, s).

Both filters are one-pole and discretised exactly for a signal that is linear between
samples (first-order hold), so a step of the filter matches the analytic response:

  high-pass (piezo gauge in voltage mode, AC coupling):  tau y' + y = tau x'
      y[n+1] = a y[n] + g (x[n+1] - x[n]),   a = exp(-h/tau),  g = (tau/h)(1 - a)
  low-pass (bandwidth limit, rise time 10-90% = 0.35/BW):  tau y' + y = x,  tau = 1/(2 pi BW)
      y[n+1] = a y[n] + (1 - g) x[n+1] + (g - a) x[n]

Both start in steady state for the first sample (a charge amplifier or an AC-coupled input
at rest reads 0 for a constant load; a low-pass at rest reads its input).
"""
from __future__ import annotations

import math

import numpy as np

from .._kernels.filters import one_pole


def highpass_coefficients(h: float, tau: float) -> tuple:
    """(b0, b1, a1) of the one-pole high-pass of time constant tau (s) at step h (s)."""
    a = math.exp(-h / tau)
    g = tau / h * (1.0 - a)
    return g, -g, -a


def lowpass_coefficients(h: float, bandwidth: float) -> tuple:
    """(b0, b1, a1) of the one-pole low-pass of -3 dB bandwidth (Hz) at step h (s)."""
    tau = 1.0 / (2.0 * math.pi * bandwidth)
    a = math.exp(-h / tau)
    g = tau / h * (1.0 - a)
    return 1.0 - g, g - a, -a


def rc_highpass(x: np.ndarray, h: float, tau: float) -> np.ndarray:
    """One-pole RC high-pass of time constant tau (s); y = 0 for a constant input."""
    return one_pole(np.ascontiguousarray(x, dtype=float), *highpass_coefficients(h, tau), float(x[0]), False)


def lowpass(x: np.ndarray, h: float, bandwidth: float) -> np.ndarray:
    """One-pole low-pass with -3 dB bandwidth (Hz); 10-90% rise time 0.35/bandwidth."""
    return one_pole(np.ascontiguousarray(x, dtype=float), *lowpass_coefficients(h, bandwidth), float(x[0]), True)
