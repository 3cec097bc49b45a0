"""The judge's rules over many shots at once: from the leading pulses each shot's record gave
(leading_pair's answers, their layout in _kernels/pulses.py), which rule refused its
figures first and the figures the rules allow, as arrays with one entry per shot. The
judge (judge.py) words a Report from one row of them; a study's batch (batch.py) takes
the figures as they are, so that a shot has the same numbers whether it was judged alone
or with thousands of others, and a batch pays a few array operations, not a Report per
shot.

The rules, in the order they refuse: the two gauges hold the same record (SAME_RECORDS);
a gauge has no leading pulse (MISSING_PULSE: ``gauges`` says why, per gauge); a channel's
bandwidth distorts its pulse (NARROW_BAND, distortion.slow); the lower pulse comes first
(LOWER_FIRST). A shot they all pass gives its amplitudes and widths; its speed figures
further need a plausible speed (``doubt``, plausibility.doubts) and the cross-correlation
a lower record that runs past its pulse's fall (``cut``)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ._kernels import pulses
from ._kernels.pulses import AMPLITUDE, BASE_WIDTH, FOUND, FWHM, LAG, PEAK, ROLE, STATUS, TIME
from .distortion import slow
from .plausibility import NO_DOUBT, doubts
from .setup import Setup

# the first rule that refused every figure of a shot (Verdicts.refused)
GIVEN, SAME_RECORDS, MISSING_PULSE, NARROW_BAND, LOWER_FIRST = range(5)
# what a gauge's leading pulse lacks (Verdicts.gauges): none (PULSE), a measurable noise,
# a record that goes on past it, a height over the noise, a peak that passes the rules
PULSE, NO_NOISE, ENDS_IN_PULSE, BELOW_NOISE, NO_PEAK = range(5)
# the figures of a Verdicts, a subset of report.FIGURES (the pulse count is the train's)
ARRAY_FIGURES = ("speed_m_per_s", "speed_xcorr_m_per_s", "averaged_amplitude_N", "amplitude_N", "total_force_N",
                 "duration_s", "base_duration_s", "width_diameters")


def role_field(answers: np.ndarray, field: int) -> np.ndarray:
    """(shots, 2): ``field`` of the upper and lower gauges' leading pulses in ``answers``."""
    return answers[:, [1 + field, 1 + ROLE + field]]


@dataclass(frozen=True, eq=False)
class Verdicts:
    """What the rules say of S shots. refused (S,): GIVEN or the first rule that refused
    every figure; gauges (S, 2): PULSE or what the upper and lower gauge's pulse lacks;
    slow (S, 2): the channel's bandwidth distorts its pulse; doubt (S,): plausibility's
    code for the speed (NO_DOUBT where the speed was not judged or passed); cut (S,): the
    lower record ends before its pulse falls to half (no cross-correlation, no train);
    flight (S,): the time between the upper and lower leading pulses (s); figures:
    ARRAY_FIGURES name -> (S,) in SI units, nan where not given."""

    refused: np.ndarray
    gauges: np.ndarray
    slow: np.ndarray
    doubt: np.ndarray
    cut: np.ndarray
    flight: np.ndarray
    figures: dict

    @property
    def speed_given(self) -> np.ndarray:
        """(S,) whether each shot's speed figures were given."""
        return (self.refused == GIVEN) & (self.doubt == NO_DOUBT)


def judge(answers: np.ndarray, span_s: np.ndarray, h_s: np.ndarray, sigma: np.ndarray | None, setup: Setup,
          bandwidth_Hz: np.ndarray, ends: np.ndarray | None = None, lower_last: np.ndarray | None = None,
          unmeasured: np.ndarray | None = None) -> Verdicts:
    """The rules on S shots' answers (S, ANSWER). span_s, h_s (S,): each record's span and
    sample interval (s); sigma (S, 2): each gauge's noise (where ``unmeasured``, by default
    where nan: not measurable, and no pulse is accepted), None for noise-free signals (no
    SNR rule); bandwidth_Hz (2,): each gauge channel's bandwidth limit (0: none known); ends
    (S, 2): a gauge's record ends inside its largest pulse (distortion.record_ends_in_pulse;
    None: not known); lower_last (S,): the lower gauge's last force sample (nan or None:
    not known)."""
    S = answers.shape[0]
    status, peak, found = answers[:, STATUS], role_field(answers, PEAK), role_field(answers, FOUND) == 1.0
    time, amp, fwhm = role_field(answers, TIME), role_field(answers, AMPLITUDE), role_field(answers, FWHM)
    rules = setup.rules
    if sigma is None:
        unmeasured = below = np.zeros((S, 2), bool)
    else:
        unmeasured = np.isnan(sigma) if unmeasured is None else unmeasured
        below = peak < rules.snr * sigma
    gauges = np.select([unmeasured, found, np.zeros((S, 2), bool) if ends is None else ends, below],
                       [NO_NOISE, PULSE, ENDS_IN_PULSE, BELOW_NOISE], NO_PEAK)
    slowed = slow(np.asarray(bandwidth_Hz, dtype=float)[None, :], fwhm)
    refused = np.select([status == pulses.SAME_RECORD, np.any(gauges != PULSE, axis=1), np.any(slowed, axis=1),
                         status == pulses.SWAPPED], [SAME_RECORDS, MISSING_PULSE, NARROW_BAND, LOWER_FIRST], GIVEN)
    given = refused == GIVEN
    distance, flight = setup.lower.position_m - setup.upper.position_m, time[:, 1] - time[:, 0]
    doubt = np.where(given, doubts(setup.limits, distance, span_s, flight, h_s, fwhm[:, 0], setup.bead_diameter_m),
                     NO_DOUBT)
    fast = given & (doubt == NO_DOUBT)
    lag = answers[:, LAG]
    last = np.full(S, np.nan) if lower_last is None else lower_last
    cut = fast & (last >= 0.5 * amp[:, 1])
    with np.errstate(divide="ignore", invalid="ignore"):
        averaged = 0.5 * (amp[:, 0] + amp[:, 1])
        amplitude = setup.beta * averaged
        speed = distance / flight
        values = {"speed_m_per_s": (fast, speed),
                  "speed_xcorr_m_per_s": (fast & ~cut, np.where(lag > 0, distance / lag, np.nan)),
                  "averaged_amplitude_N": (given, averaged), "amplitude_N": (given, amplitude),
                  "total_force_N": (given, amplitude + setup.static_force_N),
                  "duration_s": (given, fwhm[:, 0]), "base_duration_s": (given, role_field(answers, BASE_WIDTH)[:, 0]),
                  "width_diameters": (fast, fwhm[:, 0] * speed / setup.bead_diameter_m)}
    figures = {name: np.where(kept, value, np.nan) for name, (kept, value) in values.items()}
    for name in ("speed_xcorr_m_per_s", "duration_s", "base_duration_s", "width_diameters"):  # given if finite
        figures[name][~np.isfinite(figures[name])] = np.nan
    return Verdicts(refused, gauges, slowed, doubt, cut, flight, figures)
