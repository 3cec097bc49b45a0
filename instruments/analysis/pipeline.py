"""The measurement pipeline: records (real or virtual) -> calibrated forces -> pulses,
speed and amplitude, as Daraio et al. (2006) measured them. It needs no simulator: what it
knows of the physics (gauge positions, sensitivities, RC time constant, beta, F_0, bead
diameter) arrives as data in a Setup.

Speed: distance between the gauges over the time between their leading-pulse maxima (as
published), and by cross-correlation of the leading pulses. Amplitude: the mean of the two
gauges' leading-pulse amplitudes, F_m,e; the contact force amplitude F_d = beta F_m,e and
the total F_m = F_d + F_0.

No figure without a reason: each one the analysis cannot give is None, and
``Report.reasons`` says why (an envelope or untriggered record, non-finite samples, no
pulse standing ``rules.snr`` noise levels above the pre-trigger baseline, the same record
on both gauges, the lower pulse first, a speed that fails instruments.analysis.plausibility). An
implausible speed is not given: the speed figures are None and the reason quotes the value.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from ..errors import InstrumentError, check
from ..rails import clipping, rail
from ..records import ScopeRecord, Waveform, time_base_mismatch
from ._kernels import pulses
from ._kernels.pulses import AMPLITUDE, BASE_WIDTH, FOUND, FWHM, LAG, PEAK, RISE, ROLE, STATUS, TIME
from .distortion import record_ends_in_pulse, too_slow, with_clipping
from .plausibility import Limits, record_doubt, speed_doubt
from .pulses import MIN_BASELINE, PeakRules, Pulse, find_pulses, leading, noise_level
from .report import SPEED_FIGURES, Report


@dataclass(frozen=True)
class GaugeSetup:
    """A gauge as the analysis knows it: its channel, nominal position (m, down the chain),
    sensitivity (V/N; 1 gives results in volts) and RC time constant (s; None: no inversion)."""

    channel: str
    position_m: float = 0.0
    sensitivity_V_per_N: float = 1.0
    tau_s: float | None = None

    def __post_init__(self):
        check("gauge.sensitivity", self.sensitivity_V_per_N, lo=0, unit="V/N")
        if self.tau_s is not None:
            check("gauge.tau", self.tau_s, lo=0, unit="s")


@dataclass(frozen=True)
class Setup:
    """What the analysis is told: the two gauges (upper first), the wall sensor if any, the
    bead diameter (m), beta = F_d / F_m,e and F_0 (N) from the scene's numerics, the peak
    rules, the distance from the lower gauge to the wall (m) where no wall sensor says
    when the reflection arrives, the limits of a plausible speed, and the unit of the
    forces ("N", or "V" where no sensitivity converts the gauges' volts)."""

    upper: GaugeSetup
    lower: GaugeSetup
    wall: GaugeSetup | None = None
    bead_diameter_m: float = 4.76e-3
    beta: float = 1.0
    static_force_N: float = 0.0
    rules: PeakRules = field(default_factory=PeakRules)
    wall_distance_m: float | None = None
    limits: Limits = field(default_factory=Limits)
    force_unit: str = "N"

    def __post_init__(self):
        distance = self.lower.position_m - self.upper.position_m
        if not distance > 0:
            raise InstrumentError(f"the lower gauge ({self.lower.channel}, {self.lower.position_m:.6g} m) is not "
                                  f"below the upper one ({self.upper.channel}, {self.upper.position_m:.6g} m): "
                                  f"their distance is {distance:.6g} m; allowed > 0 m")
        check("beta", self.beta, lo=0, hi=10)


def record_forces(record: ScopeRecord, setup: Setup):
    """Calibrated dynamic forces (N) from a scope record: t (s from the trigger) and
    {"upper", "lower"[, "wall"]}: baseline from the pre-trigger samples, RC inverted."""
    first: Waveform | None = None
    out, t = {}, None
    for role in ("upper", "lower", "wall"):
        g = getattr(setup, role)
        if g is None:
            continue
        if g.channel not in record.waveforms:
            raise InstrumentError(f"{role} gauge channel {g.channel!r} is not in the record "
                                  f"(channels: {', '.join(record.waveforms) or 'none'})")
        w = record.waveforms[g.channel]
        h = w.preamble.x_increment
        mismatch = None if first is None else time_base_mismatch(first, w)
        if mismatch:
            raise InstrumentError(mismatch)
        if t is None:
            t, first = w.time(), w
        out[role] = pulses.conditioned(np.ascontiguousarray(w.volts(), dtype=float), int(w.preamble.trigger_index),
                                       float(h), float(g.tau_s or 0.0), float(g.sensitivity_V_per_N))
    return t, out


def record_noise(record: ScopeRecord, setup: Setup, forces: dict) -> dict:
    """role -> the noise (N) of each conditioned channel of ``forces`` (record_forces), from
    its pre-trigger samples with the floor of one code step (analysis.noise_level); None
    where the record has too short a baseline to measure it."""
    out = {}
    for role, f in forces.items():
        g = getattr(setup, role)
        w = record.waveforms[g.channel]
        out[role] = noise_level(f, w.preamble.trigger_index, _code_step(w) / g.sensitivity_V_per_N)
    return out


def _code_step(w) -> float:
    """One code step of a waveform (V): the scale factor, or for volts without codes (CSV)
    the least difference between two of its distinct values."""
    if w.codes is not None:
        return abs(w.preamble.y_multiplier)
    steps = np.diff(np.unique(w.samples))
    return float(steps.min()) if steps.size else 0.0


def analyze_forces(t: np.ndarray, forces: dict, setup: Setup, train: bool = True, noise: dict | None = None,
                   clipped: tuple = (), bandwidth: dict | None = None) -> Report:
    """Speed, amplitudes, pulse count and widths from dynamic forces (baseline 0).
    train=False leaves the solitary train uncounted (pulses None): studies that need only
    the leading pulse skip the wall channel and two peak searches. noise: role -> noise (N;
    None: unmeasurable, and no pulse is accepted) for the SNR rule; None: noise-free
    signals (the truth), no SNR rule; clipped: the rails.Clip of each gauge channel that ran
    off the scope's range (report_of); bandwidth: channel -> its bandwidth limit (Hz,
    report_of). The leading pulses and their delay come from the compiled
    _kernels/pulses.leading_pair, as in a study's batched analysis."""
    sigma = {r: math.nan if noise is None or noise.get(r) is None else float(noise[r]) for r in ("upper", "lower")}
    answer = np.empty(pulses.ANSWER)
    c = np.ascontiguousarray
    pulses.leading_pair(c(t, dtype=float), c(forces["upper"], dtype=float), c(forces["lower"], dtype=float),
                        sigma["upper"], sigma["lower"], setup.rules.as_tuple(), answer)
    return report_of(answer, t, forces, setup, train, noise, clipped, bandwidth)


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


def _snr_floor(rules: PeakRules, peak: float, sigma: float | None) -> float | None:
    """The least height of a pulse where the noise ``sigma`` is known: the relative height
    rule or ``rules.snr`` noise levels, whichever is higher (None: the height rule alone)."""
    return None if sigma is None else max(rules.height * peak, rules.snr * sigma)


def solitary_train(t, f, lead, cut: float, rules: PeakRules = PeakRules(), refine: bool = False,
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


def analyze_record(record: ScopeRecord, setup: Setup, train: bool = True) -> Report:
    """The full pipeline on one scope record, with the SNR rule on each gauge's noise.
    train=False: the leading pulse only (see analyze_forces; the wall channel is not read).
    An untriggered or envelope record, or one with non-finite samples, gives a report of
    reasons only."""
    rep = Report(beta=setup.beta, static_force_N=setup.static_force_N)
    if not record.triggered:
        return rep.refuse(f"the scope did not trigger ({record.reason or 'no reason recorded'})")
    if not train:
        setup = replace(setup, wall=None)
    roles = [r for r in ("upper", "lower", "wall") if getattr(setup, r) is not None]
    for role in roles:
        w = record.waveforms.get(getattr(setup, role).channel)
        if w is not None and w.preamble.point_format == "ENV":
            return rep.refuse(f"{w.channel}: an envelope (peak-detect) record holds min/max pairs, not samples; "
                              f"record in sample or average mode")
    t, forces = record_forces(record, setup)
    bad = [getattr(setup, r).channel for r in roles if not np.all(np.isfinite(forces[r]))]
    if bad:
        return rep.refuse(f"{', '.join(bad)}: samples that are not finite numbers (a non-finite scale factor "
                          f"or sample in the file?)")
    waves = [record.waveforms[getattr(setup, r).channel] for r in ("upper", "lower")]
    clipped = tuple(filter(None, (clipping(w.channel, rail(w), w.preamble.x_increment, w.overrange)
                                  for w in waves)))
    limits = {w.channel: w.preamble.extra.get("bandwidth_Hz") for w in waves}
    return analyze_forces(t, forces, setup, train, record_noise(record, setup, forces), clipped, limits)
