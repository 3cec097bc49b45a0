"""When the analysis cannot measure: the noise of a record's pre-trigger baseline, the
signal-to-noise rule, and the plausibility of a measured speed and pulse width.

Noise: 1.4826 x the median absolute deviation of the pre-trigger samples about their
median (the standard deviation for Gaussian noise, but blind to a stray spike or the
foot of an early pulse), never below the record's quantisation noise, one resolution step
/ sqrt(12) (an 8-bit record of a quiet line has a MAD of zero).

SNR rule: a pulse is measured only if its amplitude is at least ``PeakRules.snr`` (10)
times that noise. Gaussian noise passes 10 sigma with a probability of 8e-24 per sample,
so no record is long enough for noise alone to make a pulse, and at 10 sigma a pulse's
peak time is good to a few percent of its rise. A record with no quiet baseline (a sine,
a noise record) fails the rule: its "baseline" is as large as its "pulses".

Plausibility of a speed V = d / dt (gauge distance d over the time of flight dt):
- dt spans at least ``MIN_FLIGHT_SAMPLES`` sample intervals (fewer: the delay is not
  resolved);
- V stays below the bar speed sqrt(E / rho) of the bead material: no pulse in a chain of
  beads outruns a sound wave in the beads themselves (without a material, below 13 km/s,
  beryllium's, the fastest of any solid used for beads);
- the leading pulse's FWHM times V is 0.5 to 50 bead diameters (a solitary wave is about
  five diameters long, PHYSICS.md; a "pulse" outside that range is not one).
"""
from __future__ import annotations

import math

import numpy as np

MAX_BAR_SPEED_M_PER_S = 13_000.0
MIN_FLIGHT_SAMPLES = 3
WIDTH_DIAMETERS = (0.5, 50.0)


def resolution(values: np.ndarray, step: float | None) -> float:
    """The record's resolution (its unit): the code step where codes exist, else the least
    positive difference between the distinct values of ``values`` (0 if all are equal)."""
    if step:
        return abs(float(step))
    u = np.unique(values)
    d = np.diff(u)
    return float(d.min()) if d.size else 0.0


def baseline_noise(v: np.ndarray, n_pre: int, step: float | None = None) -> float:
    """Noise (unit of v) of the pre-trigger samples: 1.4826 x MAD, floored at step/sqrt(12)."""
    pre = np.asarray(v[:max(int(n_pre), 10)], dtype=float)
    mad = 1.4826 * float(np.median(np.abs(pre - np.median(pre))))
    return max(mad, resolution(pre, step) / math.sqrt(12.0))


def speed_problem(distance: float, flight: float, h: float, fwhm: float, diameter: float,
                  max_speed: float) -> str | None:
    """Why a speed distance / flight (m, s) is not plausible, or None. h: sample interval
    (s); fwhm: the leading pulse's FWHM (s); diameter: bead diameter (m); max_speed: the
    bead material's bar speed (m/s)."""
    speed = distance / flight
    if flight < MIN_FLIGHT_SAMPLES * h:
        return (f"the time of flight {flight:.3g} s is under {MIN_FLIGHT_SAMPLES} samples of {h:.3g} s: "
                f"the delay between the gauges is not resolved")
    if speed > max_speed:
        return (f"{speed:.4g} m/s would outrun sound in the beads themselves ({max_speed:.4g} m/s): "
                f"check the gauge distance ({distance:.4g} m) and the channels")
    width = fwhm * speed / diameter if math.isfinite(fwhm) else math.nan
    lo, hi = WIDTH_DIAMETERS
    if not lo <= width <= hi:
        return (f"{speed:.4g} m/s gives a leading pulse {width:.3g} bead diameters wide (FWHM x speed / "
                f"diameter), outside {lo:g}-{hi:g}: not a solitary wave of a granular chain")
    return None
