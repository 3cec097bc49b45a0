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

from ._kernels.filters import one_pole
from ._kernels.resample import at_positions


def rc_highpass(x: np.ndarray, h: float, tau: float) -> np.ndarray:
    """One-pole RC high-pass of time constant tau (s); y = 0 for a constant input."""
    a = math.exp(-h / tau)
    g = tau / h * (1.0 - a)
    return one_pole(np.ascontiguousarray(x, dtype=float), g, -g, -a, float(x[0]), False)


def lowpass(x: np.ndarray, h: float, bandwidth: float) -> np.ndarray:
    """One-pole low-pass with -3 dB bandwidth (Hz); 10-90% rise time 0.35/bandwidth."""
    tau = 1.0 / (2.0 * math.pi * bandwidth)
    a = math.exp(-h / tau)
    g = tau / h * (1.0 - a)
    return one_pole(np.ascontiguousarray(x, dtype=float), 1.0 - g, g - a, -a, float(x[0]), True)


def delay(x: np.ndarray, h: float, shift: float) -> np.ndarray:
    """x delayed by ``shift`` seconds (may be negative, sub-sample), by linear interpolation;
    the ends are held."""
    return at_positions(np.ascontiguousarray(x, dtype=float), np.arange(x.size) - shift / h)
