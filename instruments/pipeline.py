"""The measurement pipeline: records (real or virtual) -> calibrated forces -> pulses,
speed and amplitude, as Daraio et al. (2006) measured them. It needs no simulator: what it
knows of the physics (gauge positions, sensitivities, RC time constant, beta, F_0, bead
diameter) arrives as data in a Setup.

Speed: distance between the gauges over the time between their leading-pulse maxima (as
published), and by cross-correlation of the leading pulses. Amplitude: the mean of the two
gauges' leading-pulse amplitudes, F_m,e; the contact force amplitude F_d = beta F_m,e and
the total F_m = F_d + F_0.

No figure is left out without a reason: ``Report.reasons`` maps each missing figure to why
(no pulse, below the signal-to-noise rule, an envelope record, channels swapped or the same
record twice, non-finite samples, an implausible speed: instruments/quality.py), and
``Report.snr`` gives each gauge's leading-pulse amplitude over its baseline noise.
"""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field, replace

import numpy as np

from .analysis import PeakRules, find_pulses, invert_rc, leading, refined, remove_baseline, xcorr_delay
from .errors import InstrumentError, check
from .quality import MAX_BAR_SPEED_M_PER_S, baseline_noise, speed_problem
from .records import ScopeRecord


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
    rules, and the distance from the lower gauge to the wall (m) where no wall sensor says
    when the reflection arrives."""

    upper: GaugeSetup
    lower: GaugeSetup
    wall: GaugeSetup | None = None
    bead_diameter_m: float = 4.76e-3
    beta: float = 1.0
    static_force_N: float = 0.0
    rules: PeakRules = field(default_factory=PeakRules)
    wall_distance_m: float | None = None
    max_speed_m_per_s: float = MAX_BAR_SPEED_M_PER_S

    def __post_init__(self):
        check("gauge_distance", self.lower.position_m - self.upper.position_m, lo=0, unit="m")
        check("beta", self.beta, lo=0, hi=10)
        check("max_speed", self.max_speed_m_per_s, lo=0, unit="m/s")


FIGURES = ("speed_m_per_s", "speed_xcorr_m_per_s", "averaged_amplitude_N", "amplitude_N", "total_force_N",
           "pulses", "duration_s", "base_duration_s", "width_diameters")


def _missing(v) -> bool:
    return v is None or (isinstance(v, float) and not math.isfinite(v))


@dataclass
class Report:
    """The analysis of one shot (SI units; None where a figure could not be measured, and
    then ``reasons[figure]`` says why; ``snr``: each gauge's leading-pulse amplitude over
    its baseline noise, where the record has noise)."""

    speed_m_per_s: float | None = None
    speed_xcorr_m_per_s: float | None = None
    averaged_amplitude_N: float | None = None
    amplitude_N: float | None = None
    total_force_N: float | None = None
    beta: float | None = None
    static_force_N: float | None = None
    pulses: int | None = None
    duration_s: float | None = None
    base_duration_s: float | None = None
    width_diameters: float | None = None
    leading: dict = field(default_factory=dict)
    snr: dict = field(default_factory=dict)
    reasons: dict = field(default_factory=dict)

    def refuse(self, why: str, figures=None) -> Report:
        """Say why ``figures`` (default: every figure still missing) are left out; the first
        reason given for a figure stays."""
        for f in figures or [f for f in FIGURES if _missing(getattr(self, f))]:
            self.reasons.setdefault(f, why)
        return self

    def as_dict(self) -> dict:
        return {k: (None if isinstance(v, float) and not math.isfinite(v) else v)
                for k, v in asdict(self).items()}


@dataclass(frozen=True)
class GaugeForces:
    """Calibrated dynamic forces (N) of a record: t (s from the trigger), forces by role
    ("upper", "lower"[, "wall"]), each role's baseline noise (N) and, for a role whose
    record cannot be analysed (an envelope, non-finite samples), why."""

    t: np.ndarray
    forces: dict
    noise: dict
    unusable: dict


def record_forces(record: ScopeRecord, setup: Setup) -> GaugeForces:
    """Baseline from the pre-trigger samples, RC inverted, volts to newtons."""
    out, noise, unusable, t, base = {}, {}, {}, None, None
    for role in ("upper", "lower", "wall"):
        g = getattr(setup, role)
        if g is None:
            continue
        if g.channel not in record.waveforms:
            raise InstrumentError(f"{role} gauge channel {g.channel!r} is not in the record "
                                  f"(channels: {', '.join(record.waveforms) or 'none'})")
        w = record.waveforms[g.channel]
        p = w.preamble
        if t is None:
            t, base = w.time(), (p.points, p.x_increment, p.x_zero)
        elif (p.points, p.x_increment, p.x_zero) != base:
            raise InstrumentError(f"channel {g.channel} has another time base than the first gauge")
        v = w.volts()
        if p.point_format == "ENV":
            unusable[role] = (f"{g.channel} is an envelope (peak-detect) record: (min, max) pairs, not "
                              f"samples; record in sample or average mode")
        elif not np.all(np.isfinite(v)):
            unusable[role] = f"{g.channel} holds non-finite samples (a NaN or infinite scale factor?)"
        if role in unusable:
            v = np.zeros_like(v, dtype=float)
        v = remove_baseline(v, p.trigger_index)
        noise[role] = baseline_noise(v, p.trigger_index, p.y_multiplier if w.codes is not None else None) \
            / g.sensitivity_V_per_N
        if g.tau_s is not None:
            v = invert_rc(v, p.x_increment, g.tau_s)
        out[role] = v / g.sensitivity_V_per_N
    return GaugeForces(t, out, noise, unusable)


def analyze_forces(t: np.ndarray, forces: dict, setup: Setup, train: bool = True,
                   noise: dict | None = None) -> Report:
    """Speed, amplitudes, pulse count and widths from dynamic forces (baseline 0).
    train=False leaves the solitary train uncounted (pulses None): studies that need only
    the leading pulse skip the wall channel and two peak searches. noise: each role's
    baseline noise (N) for the signal-to-noise rule (None: noise-free forces, no rule)."""
    rules = setup.rules
    rep = Report(beta=setup.beta, static_force_N=setup.static_force_N)
    lead = {}
    for role in ("upper", "lower"):
        p = leading(find_pulses(t, forces[role], rules, refine=False), rules)
        channel = getattr(setup, role).channel
        if p is None:
            return rep.refuse(f"no pulse above the baseline on the {role} gauge ({channel})")
        if noise is not None:
            rep.snr[role] = p.amplitude / noise[role] if noise[role] > 0 else math.inf
            if rep.snr[role] < rules.snr:
                return rep.refuse(f"the {role} gauge's largest pulse ({channel}) is only {rep.snr[role]:.3g} x its "
                                  f"baseline noise; a pulse must stand {rules.snr:g} x above it")
        lead[role] = p
    if np.array_equal(forces["upper"], forces["lower"]):
        return rep.refuse(f"the upper and lower gauges ({setup.upper.channel}, {setup.lower.channel}) hold the "
                          f"same record: the same file twice?")
    up, low = refined(t, forces["upper"], lead["upper"], rules), refined(t, forces["lower"], lead["lower"], rules)
    if low.time <= up.time:
        return rep.refuse(f"the lower gauge's pulse ({setup.lower.channel}, {low.time:.4g} s) comes before the "
                          f"upper gauge's ({setup.upper.channel}, {up.time:.4g} s): channels swapped?")
    distance = setup.lower.position_m - setup.upper.position_m
    problem = speed_problem(distance, low.time - up.time, t[1] - t[0], up.fwhm, setup.bead_diameter_m,
                            setup.max_speed_m_per_s)
    if problem:
        return rep.refuse(f"implausible: {problem}")
    rep.speed_m_per_s = distance / (low.time - up.time)
    lag = xcorr_delay(t, forces["upper"], up, forces["lower"], low)
    rep.speed_xcorr_m_per_s = distance / lag if lag > 0 else None
    if rep.speed_xcorr_m_per_s is None:
        rep.refuse("the leading pulses do not cross-correlate at a positive delay", ("speed_xcorr_m_per_s",))
    rep.averaged_amplitude_N = 0.5 * (up.amplitude + low.amplitude)
    rep.amplitude_N = setup.beta * rep.averaged_amplitude_N
    rep.total_force_N = rep.amplitude_N + setup.static_force_N
    rep.duration_s = up.fwhm
    rep.base_duration_s = up.base_width
    rep.width_diameters = up.fwhm * rep.speed_m_per_s / setup.bead_diameter_m
    if train:
        cut = reflection_time(t, forces, setup, low, rep.speed_m_per_s)
        rep.pulses = len(solitary_train(t, forces["lower"], low, cut, rules))
    rep.leading = {"upper": dict(vars(up)), "lower": dict(vars(low))}  # a Pulse holds floats only
    if not train:
        rep.refuse("not counted: only the leading pulse was analysed", ("pulses",))
    return rep.refuse("the leading pulse's half-maximum or 1% crossings lie outside the record")


def solitary_train(t, f, lead, cut: float, rules: PeakRules = PeakRules(), refine: bool = False) -> list:
    """The solitary waves of a train at one gauge: pulses above 5% of the leading one, from
    the leading one until ``cut`` (s; when the wall's reflection arrives)."""
    train = find_pulses(t, f, rules, floor=0.05 * lead.amplitude, refine=refine)
    return [p for p in train if lead.time - 0.5 * lead.fwhm <= p.time < cut]


def reflection_time(t, forces, setup: Setup, low, speed) -> float:
    """When the wall's reflection of the leading pulse ``low`` reaches its gauge, less one
    FWHM (from the wall channel if there is one, else from the wall distance)."""
    if "wall" in forces:
        wall = leading(find_pulses(t, forces["wall"], setup.rules, refine=False), setup.rules)
        if wall is not None and wall.time > low.time:
            return 2 * wall.time - low.time - low.fwhm
    if setup.wall_distance_m is not None:
        return low.time + 2 * setup.wall_distance_m / speed - low.fwhm
    return math.inf


def analyze_record(record: ScopeRecord, setup: Setup, train: bool = True) -> Report:
    """The full pipeline on one scope record; an untriggered or unusable record gives a
    report whose reasons say why. train=False: the leading pulse only (see analyze_forces;
    the wall channel is not read)."""
    rep = Report(beta=setup.beta, static_force_N=setup.static_force_N)
    if not record.triggered:
        return rep.refuse(f"the scope did not trigger: {record.reason or 'no reason recorded'}")
    if not train:
        setup = replace(setup, wall=None)
    g = record_forces(record, setup)
    bad = [g.unusable[r] for r in ("upper", "lower") if r in g.unusable]
    if bad:
        return rep.refuse("; ".join(bad))
    if "wall" in g.unusable:
        g.forces.pop("wall")
    return analyze_forces(g.t, g.forces, setup, train, g.noise)
