"""Judge: the leading pulses a record gave (leading_pair's answer, its layout in
_kernels/pulses.py) to a Report: every figure they allow, and a reason for each they do
not. The rules: a pulse must stand ``rules.snr`` noise levels above the pre-trigger
baseline and pass the peak rules; the record must not end in the pulse; the two gauges must
not hold the same record, nor the lower pulse come first; the scope's bandwidth and rails
must leave the pulse undistorted (distortion.py); the speed must be one a chain can have
(plausibility.py). With a speed given, the solitary train is counted (find.py).

Speed: distance between the gauges over the time between their leading-pulse maxima (as
published), and by cross-correlation of the leading pulses. Amplitude: the mean of the two
gauges' leading-pulse amplitudes, F_m,e; the contact force amplitude F_d = beta F_m,e and
the total F_m = F_d + F_0."""
from __future__ import annotations

import math

import numpy as np

from ._kernels import pulses
from ._kernels.pulses import AMPLITUDE, BASE_WIDTH, FOUND, FWHM, LAG, PEAK, RISE, ROLE, STATUS, TIME
from .condition import MIN_BASELINE
from .distortion import record_ends_in_pulse, too_slow, with_clipping
from .find import reflection_time, solitary_train
from .plausibility import record_doubt, speed_doubt
from .pulse import Pulse
from .report import SPEED_FIGURES, Report
from .setup import Setup


def report_of(answer: np.ndarray, t: np.ndarray, forces: dict, setup: Setup, train: bool,
              noise: dict | None, clipped: tuple = (), bandwidth: dict | None = None) -> Report:
    """The Report of leading_pair's answer (its layout in _kernels/pulses.py): every figure
    it allows, a reason for each it does not, the plausibility rules, and with ``train``
    the solitary train counted on ``forces``. ``clipped``: the rails.Clip of each gauge
    channel whose record ran off the scope's range (with_clipping). ``bandwidth``: channel
    -> its bandwidth limit (Hz; None or absent: none known), whose rise time must stay
    within SLOW_FRACTION of the leading pulse's FWHM (too_slow)."""
    return with_clipping(_report(answer, t, forces, setup, train, noise, bandwidth), clipped)


def _report(answer: np.ndarray, t: np.ndarray, forces: dict, setup: Setup, train: bool,
            noise: dict | None, bandwidth: dict | None) -> Report:
    """report_of without the clipping rule."""
    rules, rep = setup.rules, Report(beta=setup.beta, static_force_N=setup.static_force_N)
    ch = {r: getattr(setup, r).channel for r in ("upper", "lower")}
    if answer[STATUS] == pulses.SAME_RECORD:
        return rep.refuse(f"{ch['upper']} and {ch['lower']} hold the same record (the same file twice?)")
    problems, lead = [], {}
    for k, r in enumerate(("upper", "lower")):
        sigma = None if noise is None else noise.get(r)
        if noise is not None and sigma is None:
            problems.append(f"{ch[r]}: fewer than {MIN_BASELINE} samples before the trigger: the noise, and so "
                            f"whether a pulse stands above it, cannot be measured")
            continue
        peak = float(answer[1 + ROLE * k + PEAK])
        if sigma is not None:
            rep.noise[ch[r]], rep.snr[ch[r]] = sigma, (peak / sigma if sigma > 0 else math.inf)
        if answer[1 + ROLE * k + FOUND] != 1.0:
            if record_ends_in_pulse(forces.get(r), sigma, rules):
                problems.append(f"{ch[r]}: the record ends during the pulse (at t = {float(t[-1]):.4g} s): a longer "
                                f"record (scope.record_length) or a later trigger")
            elif sigma is not None and peak < rules.snr * sigma:
                problems.append(f"{ch[r]}: no pulse stands {rules.snr:g} times above the pre-trigger noise "
                                f"({sigma:.3g} {setup.force_unit}): its highest excursion is "
                                f"{rep.snr[ch[r]]:.3g} times the noise")
            else:
                problems.append(f"{ch[r]}: no pulse passes the peak rules (height, prominence, width)")
            continue
        lead[r] = Pulse(*(float(answer[1 + ROLE * k + x]) for x in (TIME, AMPLITUDE, FWHM, BASE_WIDTH, RISE)))
        if sigma is not None and sigma > 0:
            rep.snr[ch[r]] = lead[r].amplitude / sigma
    if problems:
        return rep.refuse("; ".join(problems))
    slow = [too_slow(ch[r], (bandwidth or {}).get(ch[r]), lead[r].fwhm) for r in ("upper", "lower")]
    if any(slow):
        return rep.refuse("; ".join(filter(None, slow)))
    up, low = lead["upper"], lead["lower"]
    if answer[STATUS] == pulses.SWAPPED:
        return rep.refuse(f"the lower gauge's pulse ({ch['lower']}, {low.time * 1e6:.4g} us) comes before or with "
                          f"the upper gauge's ({ch['upper']}, {up.time * 1e6:.4g} us): channels swapped?")
    rep.leading = {"upper": dict(vars(up)), "lower": dict(vars(low))}  # a Pulse holds floats only
    rep.averaged_amplitude_N = 0.5 * (up.amplitude + low.amplitude)
    rep.amplitude_N = setup.beta * rep.averaged_amplitude_N
    rep.total_force_N = rep.amplitude_N + setup.static_force_N
    rep.give("duration_s", up.fwhm, f"{ch['upper']}: the leading pulse never falls to half its amplitude")
    rep.give("base_duration_s", up.base_width, f"{ch['upper']}: the leading pulse never falls to 1% of its amplitude")
    distance, flight = setup.lower.position_m - setup.upper.position_m, low.time - up.time
    doubt = (record_doubt(setup.limits, distance, float(t[-1] - t[0]))
             or speed_doubt(setup.limits, distance, flight, float(t[1] - t[0]), up.fwhm, setup.bead_diameter_m))
    if doubt:
        return rep.refuse(f"implausible speed: {doubt}", SPEED_FIGURES)
    rep.speed_m_per_s = distance / flight
    lag = float(answer[LAG])
    lower = forces.get("lower")
    if lower is not None and float(lower[-1]) >= 0.5 * low.amplitude:
        # the record ends before the lower pulse falls to half: its peak is in, its fall and the train are not
        rep.refuse(f"{ch['lower']}: the record ends during the pulse (at t = {float(t[-1]):.4g} s), before it falls "
                   f"to half its amplitude, which cuts the cross-correlation window and the train: a longer record "
                   f"(scope.record_length) or a later trigger", ("speed_xcorr_m_per_s", "pulses"))
        train = False
    else:
        rep.give("speed_xcorr_m_per_s", distance / lag if lag > 0 else math.nan,
                 "the cross-correlation of the leading pulses found no positive delay")
    rep.give("width_diameters", up.fwhm * rep.speed_m_per_s / setup.bead_diameter_m, rep.reasons.get("duration_s", ""))
    if train:
        sigma = noise.get("lower") if noise else None
        cut = reflection_time(t, forces, setup, low, rep.speed_m_per_s, noise)
        rep.pulses = len(solitary_train(t, forces["lower"], low, cut, rules, noise=sigma))
    else:
        rep.refuse("the train was not counted (leading pulse only)", ("pulses",))
    return rep

