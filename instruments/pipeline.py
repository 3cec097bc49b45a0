"""The measurement pipeline: records (real or virtual) -> calibrated forces -> pulses,
speed and amplitude, as Daraio et al. (2006) measured them. It needs no simulator: what it
knows of the physics (gauge positions, sensitivities, RC time constant, beta, F_0, bead
diameter) arrives as data in a Setup.

Speed: distance between the gauges over the time between their leading-pulse maxima (as
published), and by cross-correlation of the leading pulses. Amplitude: the mean of the two
gauges' leading-pulse amplitudes, F_m,e; the contact force amplitude F_d = beta F_m,e and
the total F_m = F_d + F_0.
"""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field, replace

import numpy as np

from .analysis import PeakRules, find_pulses, invert_rc, leading, refined, remove_baseline, xcorr_delay
from .errors import InstrumentError, check
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

    def __post_init__(self):
        check("gauge_distance", self.lower.position_m - self.upper.position_m, lo=0, unit="m")
        check("beta", self.beta, lo=0, hi=10)


@dataclass
class Report:
    """The analysis of one shot (SI units; None where a pulse was not found)."""

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

    def as_dict(self) -> dict:
        return {k: (None if isinstance(v, float) and not math.isfinite(v) else v)
                for k, v in asdict(self).items()}


def record_forces(record: ScopeRecord, setup: Setup):
    """Calibrated dynamic forces (N) from a scope record: t (s from the trigger) and
    {"upper", "lower"[, "wall"]}: baseline from the pre-trigger samples, RC inverted."""
    out, t, base = {}, None, None
    for role in ("upper", "lower", "wall"):
        g = getattr(setup, role)
        if g is None:
            continue
        if g.channel not in record.waveforms:
            raise InstrumentError(f"{role} gauge channel {g.channel!r} is not in the record "
                                  f"(channels: {', '.join(record.waveforms) or 'none'})")
        w = record.waveforms[g.channel]
        h = w.preamble.x_increment
        p = w.preamble
        if t is None:
            t, base = w.time(), (p.points, p.x_increment, p.x_zero)
        elif (p.points, p.x_increment, p.x_zero) != base:
            raise InstrumentError(f"channel {g.channel} has another time base than the first gauge")
        v = remove_baseline(w.volts(), w.preamble.trigger_index)
        if g.tau_s is not None:
            v = invert_rc(v, h, g.tau_s)
        out[role] = v / g.sensitivity_V_per_N
    return t, out


def analyze_forces(t: np.ndarray, forces: dict, setup: Setup, train: bool = True) -> Report:
    """Speed, amplitudes, pulse count and widths from dynamic forces (baseline 0).
    train=False leaves the solitary train uncounted (pulses None): studies that need only
    the leading pulse skip the wall channel and two peak searches."""
    rules = setup.rules
    up = leading(find_pulses(t, forces["upper"], rules, refine=False), rules)
    low = leading(find_pulses(t, forces["lower"], rules, refine=False), rules)
    rep = Report(beta=setup.beta, static_force_N=setup.static_force_N)
    if up is None or low is None:
        return rep
    up, low = refined(t, forces["upper"], up, rules), refined(t, forces["lower"], low, rules)
    if low.time <= up.time:
        return rep
    distance = setup.lower.position_m - setup.upper.position_m
    rep.speed_m_per_s = distance / (low.time - up.time)
    lag = xcorr_delay(t, forces["upper"], up, forces["lower"], low)
    rep.speed_xcorr_m_per_s = distance / lag if lag > 0 else None
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
    return rep


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
    """The full pipeline on one scope record; an untriggered record gives an empty report.
    train=False: the leading pulse only (see analyze_forces; the wall channel is not read)."""
    if not record.triggered:
        return Report(beta=setup.beta, static_force_N=setup.static_force_N)
    if not train:
        setup = replace(setup, wall=None)
    t, forces = record_forces(record, setup)
    return analyze_forces(t, forces, setup, train)
