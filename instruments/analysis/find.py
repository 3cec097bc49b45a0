"""Find: the pulses of a conditioned signal by the rules of scipy.signal.find_peaks
(height, distance, prominence, width; compiled in _kernels/, the same results bit for
bit), the leading one, the solitary train behind it until the wall's reflection, and the
first crest of a signal. Each pulse found is refined (refine.py) unless asked not to be."""
from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from numerics.threads import over_threads

from ..errors import InstrumentError
from ._kernels import pulses
from .pulse import DEFAULT_RULES, PeakRules, Pulse
from .refine import refined
from .setup import Setup


def find_pulses(t: np.ndarray, f: np.ndarray, rules: PeakRules = DEFAULT_RULES,
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


def leading(pulses: list, rules: PeakRules = DEFAULT_RULES):
    """The first pulse above ``rules.lead`` of the largest one (None if there is none)."""
    if not pulses:
        return None
    big = max(p.amplitude for p in pulses)
    return next(p for p in pulses if p.amplitude >= rules.lead * big)


def solitary_train(t, f, lead, cut: float, rules: PeakRules = DEFAULT_RULES, refine: bool = False,
                   noise: float | None = None) -> list:
    """The solitary waves of a train at one gauge: pulses above 5% of the leading one (and
    ``rules.snr`` times the noise, where known), from the leading one until ``cut`` (s; when
    the wall's reflection arrives). Maxima closer than the leading pulse's FWHM are one
    pulse, the highest (the first of equals): the flat top of a quantised pulse, whose
    flickers between two codes each reach the top code, is not a train of its own."""
    floor = 0.05 * lead.amplitude if noise is None else max(0.05 * lead.amplitude, rules.snr * noise)
    train: list[Pulse] = []
    for p in find_pulses(t, f, rules, floor=floor, refine=refine):
        if not lead.time - 0.5 * lead.fwhm <= p.time < cut:
            continue
        if train and p.time - train[-1].time < lead.fwhm:
            if p.amplitude > train[-1].amplitude:
                train[-1] = p
            continue
        train.append(p)
    return train


def reflection_time(t, forces, setup: Setup, low, speed, noise: dict | None = None) -> float:
    """When the wall's reflection of the leading pulse ``low`` reaches its gauge, less one
    FWHM (from the wall channel's leading pulse, above the SNR rule where its noise is
    known, if there is one; else from the wall distance)."""
    if "wall" in forces:
        f, sigma = forces["wall"], (noise or {}).get("wall")
        floor = _snr_floor(setup.rules, float(np.max(f)), sigma)
        wall = leading(find_pulses(t, f, setup.rules, floor=floor, refine=False), setup.rules)
        if wall is not None and wall.time > low.time:
            return 2 * wall.time - low.time - low.fwhm
    if setup.wall_distance_m is not None:
        return low.time + 2 * setup.wall_distance_m / speed - low.fwhm
    return math.inf


def _snr_floor(rules: PeakRules, peak: float, sigma: float | None) -> float | None:
    """The least height of a pulse where the noise ``sigma`` is known: the relative height
    rule or ``rules.snr`` noise levels, whichever is higher (None: the height rule alone)."""
    return None if sigma is None else max(rules.height * peak, rules.snr * sigma)


def first_peak_time(f: np.ndarray, h: float) -> float | None:
    """Time (s) of the first local maximum of f - f[0] above half its peak (samples every h
    s): where the pulse first crests; None where f never rises above f[0]."""
    f = np.asarray(f, dtype=float)
    if f.ndim != 1:
        raise InstrumentError(f"signal of shape {f.shape}: allowed one dimension (samples)")
    t = first_peak_times(f.reshape(1, 1, -1), [0], h)[0, 0]
    return None if math.isnan(t) else float(t)


def first_peak_times(f: np.ndarray, rows: Sequence[int] | np.ndarray, h: float) -> np.ndarray:
    """first_peak_time of rows ``rows`` of every shot of f (shots, rows, samples; samples
    every h s), on numba's threads: (shots, len(rows)) s, nan where a signal never rises
    above its first sample."""
    f = np.ascontiguousarray(f, dtype=float)
    rows = np.asarray(rows, np.int64).reshape(-1)
    if f.ndim != 3:
        raise InstrumentError(f"signals of shape {f.shape}: allowed (shots, rows, samples)")
    if rows.size and not (rows.min() >= 0 and rows.max() < f.shape[1]):
        raise InstrumentError(f"rows = {rows.tolist()}: allowed 0 .. {f.shape[1] - 1} (the signals' rows)")
    i = np.empty((f.shape[0], rows.shape[0]), np.int64)
    over_threads(f.shape[0], pulses.first_peaks, f, rows, i)
    return np.where(i >= 0, i * h, np.nan)
