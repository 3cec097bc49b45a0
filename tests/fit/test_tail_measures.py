"""The tail after the leading pulse on constructed traces where a naive measure is fooled:
a slow shoulder under a small ripple (a running mean over a fixed window takes the
shoulder's curvature and the window's mismatch with the ripple's period for ripple), and a
damped ripple too small to make a real dip (a tail that starts at a real dip or at the fall
to 1% starts past the shoulder, where the ripple has died: the magnetic chain's tail figure
jumped by ten times as a parameter moved). Tolerances are derived from the construction.

The construction: a sech^2 leading pulse (amplitude A, width w), a shoulder b A that rises
with it and decays as a logistic of time constant tau, and a sine of amplitude a A and
period P from the pulse's peak. The slow part's filter (rig.fit.observations.measures.
tail_parts) passes a cubic exactly; on e^(-t/tau) its relative error is -0.023 x^4 with
x = P / (2 tau) (the next term of its expansion), so the shoulder leaks at most
LEAK = 0.023 x^4 b A into the ripple's figure.
"""
import math

import numpy as np
import pytest

from rig.fit.observations import measures

H = 1e-7
T = np.arange(0.0, 2e-3, H)
A, TP, W = 3.0, 5e-4, 25e-6  # the leading pulse: N, s, s
P, TAU, B = 110e-6, 100e-6, 0.25  # the ripple's period, the shoulder's decay (s), its level
LEAK = 0.023 * (P / (2 * TAU)) ** 4 * B * A  # N: the shoulder's largest leak into the ripple's figure
PERIOD_ERROR = 0.01  # the period found from the ripple's crossings, within 1% of P


def _sig(x):
    return 0.5 * (1.0 + np.tanh(0.5 * x))


def parts(a: float, decay: float = math.inf):
    """(leading pulse, shoulder, ripple) of the construction (module doc), N."""
    lead = A / np.cosh((T - TP) / W) ** 2
    shoulder = B * A * _sig((T - TP) / 10e-6) * 2.0 * _sig(-(T - TP - 50e-6) / TAU)
    ripple = a * A * np.sin(2 * np.pi * (T - TP) / P) * _sig((T - TP) / 5e-6)
    return lead, shoulder, ripple * np.exp(-np.clip(T - TP, 0.0, None) / decay)


@pytest.mark.parametrize("a", [0.0, 0.01, 0.02, 0.04])
def test_a_slow_shoulder_is_reported_and_does_not_inflate_the_ripple(a):
    """The ripple's figure is a A over the peak the pipeline finds (the shoulder raises it),
    within the shoulder's leak and the period's 1% (a sine averaged over a period 1% off
    leaves 1% of itself); no ripple reads as none. The shoulder is the trace's mean over the
    tail's first period (from 1.5 FWHM after the peak), within the shoulder's slope over the
    period's error and the ripple's 1%. The earlier measure (a 100 us running mean) read
    the 0.02 ripple 9% low: its window is not the ripple's period."""
    lead, shoulder, ripple = parts(a)
    f = lead + shoulder + ripple
    peak = measures.peak(T, f)
    oscillation, level = measures.tail_parts(T, f)
    assert oscillation == pytest.approx(a * A / peak, abs=(LEAK + PERIOD_ERROR * a * A) / peak)
    assert measures.tail_excursion(T, f) == oscillation
    start = measures.leading_pulse(T, f).time + measures.TAIL_AFTER * measures.fwhm(T, f)
    first = np.abs(T - start - 0.5 * P) <= 0.5 * P
    slope = np.max(np.abs(np.diff(shoulder))) / H  # N/s
    expected = np.mean((lead + shoulder)[first]) / peak
    assert level == pytest.approx(expected, abs=(slope * PERIOD_ERROR * P + PERIOD_ERROR * a * A) / peak)
    assert measures.tail_shoulder(T, f) == level
    assert level > 0.5 * B * math.exp(-1.5)  # the shoulder is there: the logistic at its start, halved


def test_a_damped_ripple_too_small_for_a_dip_is_measured_on_the_shoulder():
    """A ripple damped in 120 us on the shoulder, too small to rise 5% from any minimum: the
    earlier measure started the tail at the fall to 1%, past the shoulder, and read a
    tenth of it. The figure lies between the damped sine's amplitude at the tail's start and
    at the end of the first period it is read over (3/4 P later and a period on), less and
    more the leak; and it is linear in the ripple (the filter is linear), so it moves with
    the ripple and does not jump."""
    decay = 120e-6
    figures, leaks = [], []
    for a in (0.02, 0.06, 0.12):
        lead, shoulder, ripple = parts(a, decay)
        f = lead + shoulder + ripple
        peak, start = measures.peak(T, f), measures.TAIL_AFTER * measures.fwhm(T, f)
        amplitude = a * A / peak
        oscillation = measures.tail_excursion(T, f)
        lo = amplitude * math.exp(-(start + 0.75 * P + (1 + PERIOD_ERROR) * P) / decay) - LEAK / peak
        hi = amplitude * math.exp(-start / decay) + LEAK / peak
        assert lo < oscillation < hi
        figures.append(oscillation / a)
        leaks.append(LEAK / peak / a)
    # linear in the ripple where it stands well above the leak: a figure per unit ripple the
    # same at 0.06 and 0.12, within the two leaks (each may add to or take from it)
    assert figures[1] == pytest.approx(figures[2], abs=leaks[1] + leaks[2])


def test_no_pulse_or_too_short_a_tail_has_no_figures():
    assert all(math.isnan(x) for x in measures.tail_parts(T, np.zeros_like(T)))
    lead, shoulder, ripple = parts(0.02)
    short = T < TP + 2 * W + P  # a record that ends before the tail holds two periods
    assert all(math.isnan(x) for x in measures.tail_parts(T[short], (lead + shoulder + ripple)[short]))
