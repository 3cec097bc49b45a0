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

from ._kernels.crossings import level_bracket
from ._kernels.filters import undo_highpass
from ._kernels.parabola import parabola
from ._kernels.peaks import local_maxima, thin_by_distance, widths_at
from ._kernels.prominence import prominence_bases
from .errors import check


def remove_baseline(y: np.ndarray, n_pre: int) -> np.ndarray:
    """y minus the mean of its first n_pre samples (at least 10, the pre-trigger part)."""
    return y - np.mean(y[:max(int(n_pre), 10)])


MIN_BASELINE = 16  # pre-trigger samples needed to measure the noise (the MAD to about 1/3)


def noise_level(y: np.ndarray, n_pre: int, step: float = 0.0) -> float | None:
    """The noise of a conditioned signal (its unit) from its first n_pre samples, the
    pre-trigger baseline: 1.4826 x their median absolute deviation (the standard deviation
    of Gaussian noise, but robust: a spike or the start of a slow signal in the baseline
    does not inflate it as it does the standard deviation), never below the quantisation
    floor step / sqrt(12) (a flat 8-bit baseline has a MAD of 0, yet a code step hides
    that much). None with fewer than MIN_BASELINE samples: the noise cannot be measured."""
    if n_pre < MIN_BASELINE:
        return None
    pre = y[:n_pre]
    mad = 1.4826 * float(np.median(np.abs(pre - np.median(pre))))
    return max(mad, abs(step) / math.sqrt(12.0))


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
    """Every pulse of f (a dynamic signal, baseline 0), in time order. ``floor`` replaces
    the relative height rule by an absolute one. refine=False gives each pulse's highest
    sample only (no parabola, widths nan): enough to count and choose pulses."""
    peak = float(np.max(f)) if f.size else 0.0
    if peak <= 0:
        return []
    h = t[1] - t[0]
    # at least half the least pulse width apart: on 8-bit noisy tops every wiggle is a local
    # maximum, and thinning them before their prominences are computed saves most of the time
    spacing = int(round(max(rules.distance, 0.5 * rules.width) / h))
    height = rules.height * peak if floor is None else floor
    f = np.ascontiguousarray(f, dtype=float)
    idx = local_maxima(f)  # find_peaks(f, height, distance): its steps in its order
    idx = idx[height <= f[idx]]
    if spacing > 1 and idx.size:
        idx = idx[thin_by_distance(idx, np.argsort(f[idx]), float(spacing))]
    # the prominence rule, applied after the distance rule as find_peaks applies it, with
    # the same bases found in one pass (find_peaks scans from each candidate: O(n) each)
    left, right = prominence_bases(f, float(height))
    left, right = left[idx], right[idx]
    prominence = f[idx] - np.maximum(f[left], f[right])
    keep = prominence >= rules.prominence * peak
    idx, prominence, left, right = idx[keep], prominence[keep], left[keep], right[keep]
    if rules.width > 0 and idx.size:  # widths only for the candidates left (noise makes many maxima)
        widths = widths_at(f, idx, 0.5, prominence, left, right)
        idx = idx[widths >= rules.width / h]
    coarse = [Pulse(float(t[i]), float(f[i]), math.nan, math.nan) for i in idx]
    return [refined(t, f, p, rules) for p in coarse] if refine else coarse


def refined(t: np.ndarray, f: np.ndarray, pulse: Pulse, rules: PeakRules = PeakRules()) -> Pulse:
    """The pulse's time and amplitude from its parabola, and its FWHM and 1% base width."""
    i = int(round((pulse.time - t[0]) / (t[1] - t[0])))
    time, amp = _vertex(t, f, i, rules.top)
    half, base = _crossings(t, f, i, 0.5 * amp), _crossings(t, f, i, 0.01 * amp)
    return Pulse(time, amp, half[1] - half[0], base[1] - base[0], time - base[0])


def leading(pulses: list, rules: PeakRules = PeakRules()):
    """The first pulse above ``rules.lead`` of the largest one (None if there is none)."""
    if not pulses:
        return None
    big = max(p.amplitude for p in pulses)
    return next(p for p in pulses if p.amplitude >= rules.lead * big)


def _vertex(t, f, i, top):
    """Least-squares parabola through the contiguous samples within ``top`` of f[i]."""
    level = f[i] * (1.0 - top)
    lo, hi = i, i
    while lo > 0 and f[lo - 1] >= level:
        lo -= 1
    while hi < f.size - 1 and f[hi + 1] >= level:
        hi += 1
    lo, hi = min(lo, i - 1), max(hi, i + 1)
    if lo < 0 or hi >= f.size:
        return float(t[i]), float(f[i])
    x = np.arange(lo - i, hi - i + 1, dtype=float)  # in samples from i
    a, b, c = parabola(x, np.ascontiguousarray(f[lo:hi + 1], dtype=float))
    if not a < 0:
        return float(t[i]), float(f[i])
    xv = -b / (2 * a)
    if not x[0] <= xv <= x[-1]:
        return float(t[i]), float(f[i])
    return float(t[i] + xv * (t[1] - t[0])), float(c - b * b / (4 * a))


def _crossings(t, f, i, level):
    """Times (s) where f crosses ``level`` before and after sample i (linear; nan if never)."""
    left, right = level_bracket(f, i, float(level))
    tl = math.nan if left < 0 else t[left] + (level - f[left]) / (f[left + 1] - f[left]) * (t[left + 1] - t[left])
    tr = math.nan if right < 0 else \
        t[right - 1] + (f[right - 1] - level) / (f[right - 1] - f[right]) * (t[right] - t[right - 1])
    return float(tl), float(tr)


def xcorr_delay(t, fa, pa: Pulse, fb, pb: Pulse) -> float:
    """Delay (s) of pulse b after pulse a by cross-correlation of the leading pulses.

    The window of a spans one FWHM either side of its maximum (the main lobe, clear of the
    next pulse of a train); b is searched within a window twice as wide around its own
    maximum; parabola through the correlation peak.
    """
    h = t[1] - t[0]
    half = pa.fwhm
    if not math.isfinite(half) or half <= 0:
        return math.nan
    ia0, ia1 = np.searchsorted(t, [pa.time - half, pa.time + half])
    ib0, ib1 = np.searchsorted(t, [pb.time - 2 * half, pb.time + 2 * half])
    a, b = fa[ia0:ia1], fb[ib0:ib1]
    if a.size < 3 or b.size <= a.size:
        return math.nan
    c = np.correlate(b, a, mode="valid")
    k = int(np.argmax(c))
    shift = 0.0
    if 0 < k < c.size - 1:
        den = c[k - 1] - 2 * c[k] + c[k + 1]
        shift = 0.5 * (c[k - 1] - c[k + 1]) / den if den != 0 else 0.0
    return float((ib0 + k + shift - ia0) * h)
