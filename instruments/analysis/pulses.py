"""Analysis of gauge signals as in Daraio et al., Phys. Rev. E 73, 026610 (2006).

Conditioning: baseline from the pre-trigger samples, and the noise from them too (see
noise_level); inversion of the one-pole RC
high-pass, x = y + (1/tau) * integral of y dt (trapezoid rule); volts to force with the
gauge's sensitivity. Pulses: the rules of scipy.signal.find_peaks (height, distance,
prominence, width; compiled in _kernels/, the same results bit for bit);
the peak time and amplitude of each pulse come from a least-squares parabola through the
samples within ``top`` of its maximum, which stays accurate on 8-bit records whose tops are
plateaus of equal codes; widths are where the pulse crosses 50% (FWHM) and 1% (base) of its
amplitude, interpolated linearly. Time of flight: between leading-pulse maxima, and by
cross-correlating the leading pulses with a parabola through the correlation peak.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._kernels.filters import undo_highpass
from ..errors import check
from ._kernels import pulses

MIN_BASELINE = pulses.MIN_BASELINE  # pre-trigger samples needed to measure the noise


def noise_level(y: np.ndarray, n_pre: int, step: float = 0.0) -> float | None:
    """The noise of a conditioned signal (its unit) from its first n_pre samples, the
    pre-trigger baseline: 1.4826 x their median absolute deviation (the standard deviation
    of Gaussian noise, but robust: a spike or the start of a slow signal in the baseline
    does not inflate it as it does the standard deviation), never below the quantisation
    floor step / sqrt(12) (a flat 8-bit baseline has a MAD of 0, yet a code step hides
    that much). None with fewer than MIN_BASELINE samples: the noise cannot be measured."""
    sigma = pulses.noise_level(np.ascontiguousarray(y, dtype=float), int(n_pre), float(step))
    return None if math.isnan(sigma) else float(sigma)


def first_peak_time(f: np.ndarray, h: float) -> float | None:
    """Time (s) of the first local maximum of f - f[0] above half its peak (samples every h
    s): where the pulse first crests; None where f never rises above f[0]."""
    i = pulses.first_peak(np.ascontiguousarray(f, dtype=float))
    return None if i < 0 else i * h


def invert_rc(y: np.ndarray, h: float, tau: float) -> np.ndarray:
    """Undo a one-pole RC high-pass of time constant tau (s): x = y + (1/tau) int y dt."""
    return undo_highpass(np.ascontiguousarray(y, dtype=float), float(h), float(tau))


@dataclass(frozen=True)
class PeakRules:
    """Which maxima are pulses. height, prominence: fractions of the record's maximum;
    distance: least spacing of pulses (s); width: least width of a pulse at half its
    prominence (s; rejects noise spikes, which are a sample or two wide); top: fraction of a
    pulse's amplitude over which its parabola is fitted; lead: the leading pulse is the
    first one above this fraction of the record's largest pulse; snr: where the noise is
    known, a pulse must stand this many noise levels above the baseline. 8: a record of
    1e7 Gaussian samples exceeds 6.4 sigma about once in a thousand records
    (1e7 x Q(6.4) = 8e-4), and the margin to 8 covers the MAD's own scatter on a short
    baseline and noise tails heavier than Gaussian."""

    height: float = 0.1
    prominence: float = 0.05
    distance: float = 0.0
    width: float = 2e-6
    top: float = 0.05
    lead: float = 0.3
    snr: float = 8.0

    def as_tuple(self) -> tuple:
        """(height, prominence, top, lead, snr, distance, width): the compiled analysis' form."""
        return (float(self.height), float(self.prominence), float(self.top), float(self.lead), float(self.snr),
                float(self.distance), float(self.width))

    def __post_init__(self):
        check("peaks.snr", self.snr, lo=0, hi=math.inf, hi_closed=False)
        for name in ("height", "prominence", "top", "lead"):
            check(f"peaks.{name}", getattr(self, name), lo=0, hi=1)
        check("peaks.distance", self.distance, lo=0, lo_closed=True, unit="s")
        check("peaks.width", self.width, lo=0, lo_closed=True, unit="s")


@dataclass(frozen=True)
class Pulse:
    """One pulse: time of its maximum (s), amplitude (same unit as the signal), full width
    at half maximum and at 1% of the amplitude, and rise from 1% to the maximum (s, nan
    where the signal never falls there). In a train the 1% width runs into the next pulse;
    twice the rise is then the pulse's own width."""

    time: float
    amplitude: float
    fwhm: float
    base_width: float
    rise: float = math.nan


def find_pulses(t: np.ndarray, f: np.ndarray, rules: PeakRules = PeakRules(),
                floor: float | None = None, refine: bool = True) -> list:
    """Every pulse of f (a dynamic signal, baseline 0), in time order, by find_peaks' rules
    (compiled in _kernels/pulses.py: candidates). ``floor`` replaces the relative height
    rule by an absolute one. refine=False gives each pulse's highest sample only (no
    parabola, widths nan): enough to count and choose pulses."""
    f = np.ascontiguousarray(f, dtype=float)
    peak = float(np.max(f)) if f.size else 0.0
    if peak <= 0:
        return []
    h = t[1] - t[0]
    # at least half the least pulse width apart: on 8-bit noisy tops every wiggle is a local
    # maximum, and thinning them before their prominences are computed saves most of the time
    spacing = int(np.rint(max(rules.distance, 0.5 * rules.width) / h))
    height = rules.height * peak if floor is None else floor
    idx = pulses.candidates(f, float(height), rules.prominence * peak, spacing, rules.width / h)
    coarse = [Pulse(float(t[i]), float(f[i]), math.nan, math.nan) for i in idx]
    return [refined(t, f, p, rules) for p in coarse] if refine else coarse


def refined(t: np.ndarray, f: np.ndarray, pulse: Pulse, rules: PeakRules = PeakRules()) -> Pulse:
    """The pulse's time and amplitude from its parabola, and its FWHM and 1% base width."""
    i = int(np.rint((pulse.time - t[0]) / (t[1] - t[0])))
    return Pulse(*(float(x) for x in pulses.refine(np.ascontiguousarray(t, dtype=float),
                                                   np.ascontiguousarray(f, dtype=float), i, rules.top)))


def leading(pulses: list, rules: PeakRules = PeakRules()):
    """The first pulse above ``rules.lead`` of the largest one (None if there is none)."""
    if not pulses:
        return None
    big = max(p.amplitude for p in pulses)
    return next(p for p in pulses if p.amplitude >= rules.lead * big)


def xcorr_delay(t, fa, pa: Pulse, fb, pb: Pulse) -> float:
    """Delay (s) of pulse b after pulse a by cross-correlation of the leading pulses.

    The window of a spans one FWHM either side of its maximum (the main lobe, clear of the
    next pulse of a train); b is searched within a window twice as wide around its own
    maximum; parabola through the correlation peak (compiled: _kernels/pulses.py)."""
    c = np.ascontiguousarray
    return float(pulses.xcorr_lag(c(t, dtype=float), c(fa, dtype=float), pa.time, pa.fwhm, c(fb, dtype=float),
                                  pb.time))
