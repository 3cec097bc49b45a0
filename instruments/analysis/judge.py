"""Judge: the leading pulses a record gave (leading_pair's answer, its layout in
_kernels/pulses.py) to a Report: every figure they allow, and a reason for each they do
not. The rules (verdicts.py, which applies them to many shots at once: here to one, and the
Report words what they said): a pulse must stand ``rules.snr`` noise levels above the
pre-trigger baseline and pass the peak rules; the record must not end in the pulse; the two
gauges must not hold the same record, nor the lower pulse come first; the scope's bandwidth
and rails must leave the pulse undistorted (distortion.py); the speed must be one a chain
can have (plausibility.py). With a speed given, the solitary train is counted (find.py).

Speed: distance between the gauges over the time between their leading-pulse maxima (as
published), and by cross-correlation of the leading pulses. Amplitude: the mean of the two
gauges' leading-pulse amplitudes, F_m,e; the contact force amplitude F_d = beta F_m,e and
the total F_m = F_d + F_0."""
from __future__ import annotations

import math

import numpy as np

from . import verdicts
from ._kernels.pulses import AMPLITUDE, BASE_WIDTH, FWHM, PEAK, RISE, TIME
from .condition import MIN_BASELINE
from .distortion import record_ends_in_pulse, too_slow, with_clipping
from .find import reflection_time, solitary_train
from .plausibility import NO_DOUBT, doubt_text
from .pulse import Pulse
from .report import SPEED_FIGURES, Report
from .setup import Setup
from .verdicts import Verdicts, role_field

ROLES = ("upper", "lower")


def report_of(answer: np.ndarray, t: np.ndarray, forces: dict, setup: Setup, train: bool,
              noise: dict | None, clipped: tuple = (), bandwidth: dict | None = None) -> Report:
    """The Report of leading_pair's answer (its layout in _kernels/pulses.py): every figure
    it allows, a reason for each it does not, the plausibility rules, and with ``train``
    the solitary train counted on ``forces``. ``clipped``: the rails.Clip of each gauge
    channel whose record ran off the scope's range (with_clipping). ``bandwidth``: channel
    -> its bandwidth limit (Hz; None or absent: none known), whose rise time must stay
    within SLOW_FRACTION of the leading pulse's FWHM (too_slow)."""
    given = {} if noise is None else noise
    sigma = None if noise is None else np.array([[math.nan if given.get(r) is None else given[r] for r in ROLES]])
    ends = np.array([[record_ends_in_pulse(forces.get(r), given.get(r), setup.rules) for r in ROLES]])
    lower = forces.get("lower")
    v = verdicts.judge(answer[None], np.array([t[-1] - t[0]]), np.array([t[1] - t[0]]), sigma, setup,
                       bandwidths(setup, bandwidth), ends, np.array([math.nan if lower is None else float(lower[-1])]),
                       np.array([[given.get(r) is None for r in ROLES]]))
    return with_clipping(report_at(v, 0, answer, t, forces, setup, train, noise, bandwidth), clipped)


def bandwidths(setup: Setup, bandwidth: dict | None) -> np.ndarray:
    """(2,) the upper and lower gauge channels' bandwidth limits (Hz; 0: none known)."""
    limits = [(bandwidth or {}).get(getattr(setup, r).channel) for r in ROLES]
    return np.array([0.0 if b is None else b for b in limits], dtype=float)


def report_at(v: Verdicts, s: int, answer: np.ndarray, t: np.ndarray, forces: dict, setup: Setup, train: bool,
              noise: dict | None, bandwidth: dict | None) -> Report:
    """Shot s's Report from the verdicts ``v`` on its answer (report_of's arguments), without
    the clipping rule: the figures as v has them, each refusal worded."""
    rules, rep = setup.rules, Report(beta=setup.beta, static_force_N=setup.static_force_N)
    ch = {r: getattr(setup, r).channel for r in ROLES}
    refused = v.refused[s]
    if refused == verdicts.SAME_RECORDS:
        return rep.refuse(f"{ch['upper']} and {ch['lower']} hold the same record (the same file twice?)")
    fields = np.stack([role_field(answer[None], f)[0] for f in (TIME, AMPLITUDE, FWHM, BASE_WIDTH, RISE, PEAK)])
    pulse = {r: Pulse(*(float(x) for x in fields[:-1, k])) for k, r in enumerate(ROLES)}
    problems = []
    for k, r in enumerate(ROLES):
        sigma, peak, why = None if noise is None else noise.get(r), float(fields[-1, k]), v.gauges[s, k]
        if why == verdicts.NO_NOISE:
            problems.append(f"{ch[r]}: fewer than {MIN_BASELINE} samples before the trigger: the noise, and so "
                            f"whether a pulse stands above it, cannot be measured")
            continue
        if sigma is not None:
            rep.noise[ch[r]], rep.snr[ch[r]] = sigma, (peak / sigma if sigma > 0 else math.inf)
        if why == verdicts.ENDS_IN_PULSE:
            problems.append(f"{ch[r]}: the record ends during the pulse (at t = {float(t[-1]):.4g} s): a longer "
                            f"record (scope.record_length) or a later trigger")
        elif why == verdicts.BELOW_NOISE:
            problems.append(f"{ch[r]}: no pulse stands {rules.snr:g} times above the pre-trigger noise "
                            f"({sigma:.3g} {setup.force_unit}): its highest excursion is "
                            f"{rep.snr[ch[r]]:.3g} times the noise")
        elif why == verdicts.NO_PEAK:
            problems.append(f"{ch[r]}: no pulse passes the peak rules (height, prominence, width)")
        elif sigma is not None and sigma > 0:
            rep.snr[ch[r]] = pulse[r].amplitude / sigma
    if refused == verdicts.MISSING_PULSE:
        return rep.refuse("; ".join(problems))
    if refused == verdicts.NARROW_BAND:
        return rep.refuse("; ".join(too_slow(ch[r], (bandwidth or {}).get(ch[r]), pulse[r].fwhm)
                                    for k, r in enumerate(ROLES) if v.slow[s, k]))
    up, low = pulse["upper"], pulse["lower"]
    if refused == verdicts.LOWER_FIRST:
        return rep.refuse(f"the lower gauge's pulse ({ch['lower']}, {low.time * 1e6:.4g} us) comes before or with "
                          f"the upper gauge's ({ch['upper']}, {up.time * 1e6:.4g} us): channels swapped?")
    figures = {name: float(x[s]) for name, x in v.figures.items()}
    rep.leading = {"upper": dict(vars(up)), "lower": dict(vars(low))}  # a Pulse holds floats only
    rep.averaged_amplitude_N, rep.amplitude_N = figures["averaged_amplitude_N"], figures["amplitude_N"]
    rep.total_force_N = figures["total_force_N"]
    rep.give("duration_s", figures["duration_s"], f"{ch['upper']}: the leading pulse never falls to half its amplitude")
    rep.give("base_duration_s", figures["base_duration_s"],
             f"{ch['upper']}: the leading pulse never falls to 1% of its amplitude")
    if v.doubt[s] != NO_DOUBT:
        distance = setup.lower.position_m - setup.upper.position_m
        said = doubt_text(int(v.doubt[s]), setup.limits, distance, float(t[-1] - t[0]), low.time - up.time,
                          float(t[1] - t[0]), up.fwhm, setup.bead_diameter_m)
        return rep.refuse(f"implausible speed: {said}", SPEED_FIGURES)
    rep.speed_m_per_s = figures["speed_m_per_s"]
    if v.cut[s]:  # the record ends before the lower pulse falls to half: its peak is in, its fall and the train are not
        rep.refuse(f"{ch['lower']}: the record ends during the pulse (at t = {float(t[-1]):.4g} s), before it falls "
                   f"to half its amplitude, which cuts the cross-correlation window and the train: a longer record "
                   f"(scope.record_length) or a later trigger", ("speed_xcorr_m_per_s", "pulses"))
        train = False
    else:
        rep.give("speed_xcorr_m_per_s", figures["speed_xcorr_m_per_s"],
                 "the cross-correlation of the leading pulses found no positive delay")
    rep.give("width_diameters", figures["width_diameters"], rep.reasons.get("duration_s", ""))
    if train:
        sigma = noise.get("lower") if noise else None
        cut = reflection_time(t, forces, setup, low, rep.speed_m_per_s, noise)
        rep.pulses = len(solitary_train(t, forces["lower"], low, cut, rules, noise=sigma))
    else:
        rep.refuse("the train was not counted (leading pulse only)", ("pulses",))
    return rep
