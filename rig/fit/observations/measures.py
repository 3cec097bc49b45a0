"""Figures of a force signal, pure numpy on (t, f): t the sample times (s, uniform), f a
dynamic force (N, its static value removed: baseline 0). Each returns nan where the figure
is not defined on the signal (no pulse, a pulse cut off by the record's end), never None.

The leading pulse is the measurement pipeline's (instruments.analysis: the first pulse
above 30% of the record's largest, its peak time and amplitude from a parabola through its
top), so these figures and `rig shot`'s analysis agree on which pulse they describe.
"""
from __future__ import annotations

import math

import numpy as np

from instruments.analysis import Pulse, find_pulses, leading

DURATION_LEVEL = 0.1
"""A pulse's full duration runs from its rise through this fraction of its amplitude."""
TRAIN_HEIGHT = 0.1
"""A pulse of a train stands at least this fraction of the leading pulse's amplitude."""
TRAIN_DIP = 0.5
"""Two maxima are two pulses where the signal between them falls below this fraction of
the smaller one (a shoulder or a ripple on one pulse is not a second pulse)."""
DIP_DEPTH = 0.05
"""A minimum after the leading pulse's peak ends the pulse only where the signal rises
again from it by at least this fraction of the pulse's amplitude before the next minimum
(a real dip between two pulses, not a ripple on a shock-like pulse's slow fall)."""
FLAT_TOP = 0.6
"""A leading pulse is flat-topped or shock-like where its time above 90% of its amplitude
is more than this fraction of its FWHM (a Gaussian: 0.39; a sech^2 solitary wave: 0.37)."""
TAIL_AFTER = 1.5
"""The tail begins this many FWHMs of the leading pulse after its peak: a sech^2 solitary
wave has fallen to 2% there, a Gaussian to 0.2%. A fixed multiple of the pulse's own width
moves continuously with the trace; a start at a minimum or a level does not (a minimum
vanishes where the ripple's slope falls below the shoulder's, and the start then jumps past
the shoulder)."""
TAIL_WINDOW = 100e-6
"""s: the first pass's running mean, whose residual's crossings give the tail's period (and
the period where the tail has fewer than three crossings)."""
TAIL_CROSSING = 1e-3
"""A crossing of the first pass's residual counts once it passes this fraction of the
leading pulse's amplitude on the other side (rounding noise on a smooth shoulder is none)."""
TAIL_SPAN = 400e-6
"""s: how long after the leading pulse's end the tail is examined."""


def leading_pulse(t: np.ndarray, f: np.ndarray) -> Pulse | None:
    """The pipeline's leading pulse of f (None where f has no pulse)."""
    f = np.ascontiguousarray(f, dtype=float)
    return leading(find_pulses(np.asarray(t, dtype=float), f)) if f.size >= 3 else None


def peak(t: np.ndarray, f: np.ndarray) -> float:
    """The leading pulse's amplitude (f's unit, from the parabola through its top)."""
    p = leading_pulse(t, f)
    return math.nan if p is None else p.amplitude


def fwhm(t: np.ndarray, f: np.ndarray) -> float:
    """The leading pulse's full width at half its amplitude (s; the crossings of 50% of the
    amplitude, interpolated linearly between samples)."""
    p = leading_pulse(t, f)
    return math.nan if p is None else p.fwhm


def _top_index(t: np.ndarray, f: np.ndarray, p: Pulse) -> int:
    """The sample of p's maximum."""
    h = t[1] - t[0]
    i = int(np.clip(np.rint((p.time - t[0]) / h), 0, f.size - 1))
    lo, hi = max(i - 3, 0), min(i + 4, f.size)
    return lo + int(np.argmax(f[lo:hi]))


def _crossing(t: np.ndarray, f: np.ndarray, k: int, level: float) -> float:
    """Where f crosses ``level`` between samples k and k + 1 (s, linear)."""
    return float(t[k] + (level - f[k]) / (f[k + 1] - f[k]) * (t[k + 1] - t[k]))


def pulse_span(t: np.ndarray, f: np.ndarray, level: float = DURATION_LEVEL) -> tuple:
    """(start, end) of the leading pulse (s): start where it rises through ``level`` x its
    amplitude, end the earlier of where it falls through that level and its first real dip
    after the peak (a minimum the signal rises from again by DIP_DEPTH of the amplitude
    before its next minimum: in a train the next pulse rises before this one has fallen; a
    ripple on the fall is no end), at the vertex of a parabola through the minimum's
    samples. (nan, nan) where the record has no pulse or cuts it off."""
    t, f = np.asarray(t, dtype=float), np.asarray(f, dtype=float)
    p = leading_pulse(t, f)
    if p is None:
        return math.nan, math.nan
    i, cut = _top_index(t, f, p), level * p.amplitude
    below = np.flatnonzero(f[:i + 1] <= cut)
    if not below.size:
        return math.nan, math.nan
    start = _crossing(t, f, int(below[-1]), cut)
    after = f[i:]
    fall = np.flatnonzero(after <= cut)
    end = _crossing(t, f, i + int(fall[0]) - 1, cut) if fall.size else math.inf
    d = np.diff(after)
    turns = np.flatnonzero((d[:-1] <= 0) & (d[1:] > 0)) + 1  # samples after the peak with f rising after them
    real = [k for k, nxt in zip(turns.tolist(), turns[1:].tolist() + [after.size])
            if after[k:nxt].max() - after[k] >= DIP_DEPTH * p.amplitude]
    if real:
        m = i + real[0]
        den = f[m - 1] - 2.0 * f[m] + f[m + 1]
        shift = 0.5 * (f[m - 1] - f[m + 1]) / den if den > 0 else 0.0
        end = min(end, float(t[m] + shift * (t[1] - t[0])))
    return (start, end) if math.isfinite(end) else (math.nan, math.nan)


def full_duration(t: np.ndarray, f: np.ndarray, level: float = DURATION_LEVEL) -> float:
    """The leading pulse's full duration (s): from its rise through ``level`` (10%) of its
    amplitude to the earlier of its fall through that level and its first real dip after
    the peak (pulse_span)."""
    start, end = pulse_span(t, f, level)
    return end - start


def top_fraction(t: np.ndarray, f: np.ndarray) -> float:
    """The leading pulse's time above 90% of its amplitude over its FWHM: about 0.35-0.4
    for a bell-shaped pulse (Gaussian 0.39, sech^2 0.37), towards 1 for a flat-topped or
    shock-like one (flagged above FLAT_TOP). nan without a pulse."""
    t, f = np.asarray(t, dtype=float), np.asarray(f, dtype=float)
    p = leading_pulse(t, f)
    if p is None or not p.fwhm > 0:
        return math.nan
    i = _top_index(t, f, p)
    cut = 0.9 * p.amplitude
    up, down = np.flatnonzero(f[:i + 1] < cut), np.flatnonzero(f[i:] < cut)
    if not (up.size and down.size):
        return math.nan
    k, j = int(up[-1]), i + int(down[0]) - 1
    return (_crossing(t, f, j, cut) - _crossing(t, f, k, cut)) / p.fwhm


def pulses_in_train(t: np.ndarray, f: np.ndarray, until: float = math.inf, height: float = TRAIN_HEIGHT,
                    dip: float = TRAIN_DIP) -> float:
    """How many pulses the train has, the leading one included, up to time ``until`` (s):
    local maxima from the leading pulse on that stand at least ``height`` (10%) of the
    leading pulse's amplitude, each counted where the signal fell below ``dip`` (50%) of
    the smaller of it and the last counted pulse in between (else it is the same pulse: a
    higher crest of it replaces the last one). Pulses before the leading one (a precursor
    below 30% of the largest) are not counted. nan without a pulse."""
    t, f = np.asarray(t, dtype=float), np.asarray(f, dtype=float)
    p = leading_pulse(t, f)
    if p is None:
        return math.nan
    i = _top_index(t, f, p)
    stop = int(np.searchsorted(t, until, side="right")) if math.isfinite(until) else f.size
    seg = f[i:stop]
    tops = 1 + np.flatnonzero((seg[1:-1] > seg[:-2]) & (seg[1:-1] >= seg[2:]))
    count, last = 1, 0
    for k in tops.tolist():
        low = float(np.min(seg[last:k]))
        if seg[k] >= height * p.amplitude and low <= dip * min(seg[last], seg[k]):
            count, last = count + 1, k
        elif seg[k] > seg[last] and low > dip * min(seg[last], seg[k]):
            last = k
    return float(count)


def _tail_start(t: np.ndarray, p: Pulse, after: float) -> int:
    """The tail's first sample: ``after`` FWHMs after the leading pulse's peak."""
    return int(np.searchsorted(t, p.time + after * p.fwhm))


def _running_mean(x: np.ndarray, n: int) -> np.ndarray:
    """The mean of x over n samples; element j is centred on sample j + n // 2."""
    c = np.concatenate(([0.0], np.cumsum(x)))
    return (c[n:] - c[:-n]) / n


def _odd(samples: float) -> int:
    return 2 * int(round(0.5 * samples)) + 1


def _period(seg: np.ndarray, h: float, window: float, noise: float) -> float:
    """The tail's oscillation period (s): twice the median spacing of the crossings of the
    residual about the running mean over ``window`` (a crossing counted once the residual
    passes ``noise`` on the other side); ``window`` where there are fewer than three."""
    n = _odd(window / h)
    if seg.size <= n:
        return window
    r = seg[n // 2: n // 2 + seg.size - n + 1] - _running_mean(seg, n)
    out = np.flatnonzero(np.abs(r) > noise)
    turn = out[1:][np.sign(r[out[1:]]) != np.sign(r[out[:-1]])]
    return float(2.0 * np.median(np.diff(turn)) * h) if turn.size >= 3 else window


def tail_parts(t: np.ndarray, f: np.ndarray, until: float = math.inf, window: float = TAIL_WINDOW,
               span: float = TAIL_SPAN) -> tuple[float, float]:
    """(oscillation, shoulder) of the tail after the leading pulse, each over the leading
    pulse's amplitude. The tail: the ``span`` (400 us, at most to ``until``, s) from its
    start, TAIL_AFTER (1.5) FWHMs of the leading pulse after its peak. Its period P: twice
    the median spacing of its crossings of a first running mean over ``window`` (100 us;
    ``window`` where it crosses fewer than 3 times). Its slow part S: the running mean over
    P with the mean's curvature bias taken out, S = M - (P^2 / 24) M'' (M'' a second
    difference over P/4), which removes a sine of period P and passes a cubic unchanged (a
    running mean alone is off by P^2 f'' / 24: on a shoulder of 0.25 decaying over one
    period that is 0.01, as large as the ripple). oscillation: half the peak-to-peak of f -
    S where S's support (3P/4 each side) lies in the tail; shoulder: the mean of f over the
    tail's first period (the slow, non-oscillating level the tail starts at). (nan, nan)
    where the tail is shorter than 2 P or there is no pulse."""
    t, f = np.asarray(t, dtype=float), np.asarray(f, dtype=float)
    p = leading_pulse(t, f)
    if p is None or not p.fwhm > 0:
        return math.nan, math.nan
    k0, h = _tail_start(t, p, TAIL_AFTER), t[1] - t[0]
    seg = f[k0:][t[k0:] <= min(t[k0] + span, until)]
    n = _odd(_period(seg, h, window, TAIL_CROSSING * p.amplitude) / h)
    q = max(n // 4, 1)  # P/4: the second difference's step
    if seg.size < 2 * n:
        return math.nan, math.nan
    m = _running_mean(seg, n)
    slow = m[q:m.size - q] - (n * n / 24.0) * (m[2 * q:] - 2.0 * m[q:m.size - q] + m[:m.size - 2 * q]) / (q * q)
    r = seg[n // 2 + q: n // 2 + q + slow.size] - slow
    return float(0.5 * (np.max(r) - np.min(r)) / p.amplitude), float(np.mean(seg[:n]) / p.amplitude)


def tail_excursion(t: np.ndarray, f: np.ndarray, until: float = math.inf, window: float = TAIL_WINDOW,
                   span: float = TAIL_SPAN) -> float:
    """The oscillating tail after the leading pulse, relative to that pulse: half the
    peak-to-peak excursion of f about its slow part (tail_parts), so a slow shoulder does not
    count. A sine of amplitude a on a slow drift or shoulder gives a / amplitude. nan where
    the tail is too short or there is no pulse."""
    return tail_parts(t, f, until, window, span)[0]


def tail_shoulder(t: np.ndarray, f: np.ndarray, until: float = math.inf, window: float = TAIL_WINDOW,
                  span: float = TAIL_SPAN) -> float:
    """The tail's slow shoulder relative to the leading pulse: the mean of f over the tail's
    first oscillation period (tail_parts), which a sine of that period leaves unchanged. nan
    where the tail is too short or there is no pulse."""
    return tail_parts(t, f, until, window, span)[1]


def pulse_speed(t: np.ndarray, f_from: np.ndarray, f_to: np.ndarray, distance: float) -> float:
    """The leading pulse's speed (m/s) over ``distance`` (m) from the bead of f_from to the
    bead of f_to: the distance over the time between the leading pulse's peaks (the
    pipeline's time of flight between maxima, Daraio et al. 2006). nan where either has no
    pulse or they come in the wrong order."""
    a, b = leading_pulse(t, f_from), leading_pulse(t, f_to)
    if a is None or b is None or not b.time > a.time:
        return math.nan
    return float(distance / (b.time - a.time))
