"""What a virtual shot measures, analysed three ways (the blocks of `rig shot --json`).

truth: the pipeline on the noise-free ground truth at the nominal gauge positions, as the
published numerics were analysed; F_d is the mean over the two gauge beads of the maximum
dynamic contact force during the leading pulse, and beta = F_d / F_m,n.
measured: the scope records through the full pipeline, told only what an experimenter
knows (nominal positions and sensitivities, the RC time constant, beta and F_0 from the
truth).
theory: Eq (2) at F_0 and Eq (1) at the truth amplitude.
"""
from __future__ import annotations

import math

import numpy as np

from instruments.analysis import GaugeSetup, PeakRules, Setup, analyze_forces, analyze_record
from instruments.analysis.report import Report
from rig.errors import RigError
from rig.theory.longwave import solitary_wave_speed, sound_speed


def setup_for(rig, beta: float = 1.0, static_force: float = 0.0, nominal: bool = True) -> Setup:
    """The analysis Setup of a rig's gauges (upper = the higher of the first two)."""
    gauges = sorted(rig.gauges, key=lambda g: g.bead)
    if len(gauges) < 2:
        raise RigError("the analysis needs two gauge beads in the scene")
    x = rig.chain.equilibrium_positions()
    up, low = gauges[0], gauges[1]
    wall = None
    if rig.wall_sensor is not None:
        ws = rig.wall_sensor
        wall = GaugeSetup(ws.channel, float(rig.chain.wall_position()), ws.settings.sensitivity, ws.settings.tau)
    return Setup(GaugeSetup(up.channel, float(x[up.bead]), up.settings.sensitivity, up.settings.tau),
                 GaugeSetup(low.channel, float(x[low.bead]), low.settings.sensitivity, low.settings.tau), wall,
                 rig.chain.beads[up.bead].diameter, beta, static_force, PeakRules(),
                 float(rig.chain.wall_position() - x[low.bead]))


def midway_static_force(rig) -> float:
    """F_0 (N) at the contact midway between the two gauge beads."""
    j1, j2 = sorted(g.bead for g in rig.gauges)[:2]
    return float(rig.chain.static_forces()[(j1 + 1 + j2) // 2])


TAIL_FWHM = 3.0
"""The leading pulse has passed a gauge this many full widths after it peaks there."""


def leading_end(report: Report) -> float | None:
    """When the leading pulse of ``report`` has passed its last gauge (s from the impact):
    its peak time there + TAIL_FWHM full widths. None where the report has no leading
    pulse or its width is unknown (a pulse cut off by the record's end)."""
    last = (report.leading or {}).get("lower") or (report.leading or {}).get("upper")
    if not last or not math.isfinite(last.get("fwhm", math.nan)) or not last["fwhm"] > 0:
        return None
    return last["time"] + TAIL_FWHM * last["fwhm"]


def truth_report(rig, truth) -> Report:
    """The pipeline on the noise-free truth, with F_d from the contact forces."""
    F0 = midway_static_force(rig)
    setup = setup_for(rig, 1.0, F0)
    h = truth.sample_interval
    by_channel = {g.channel: g for g in truth.gauges.values()}
    up, low = by_channel[setup.upper.channel], by_channel[setup.lower.channel]
    forces = {"upper": up.average_force - up.average_force[0],
              "lower": low.average_force - low.average_force[0]}
    if truth.wall_force is not None:
        forces["wall"] = truth.wall_force - truth.wall_force[0]
    t = np.arange(forces["upper"].size) * h
    rep = analyze_forces(t, forces, setup)
    if rep.speed_m_per_s is None or rep.averaged_amplitude_N is None:
        return rep
    peaks = []
    for g, lead in ((up, rep.leading["upper"]), (low, rep.leading["lower"])):
        half = lead["fwhm"] if math.isfinite(lead["fwhm"]) else h  # a pulse cut off by the record's end
        window = np.abs(t - lead["time"]) <= max(half, h)
        peaks.append(max(np.max(g.contact_above[window] - g.static_above_N),
                         np.max(g.contact_below[window] - g.static_below_N)))
    rep.amplitude_N = float(np.mean(peaks))
    rep.beta = rep.amplitude_N / rep.averaged_amplitude_N
    rep.total_force_N = rep.amplitude_N + F0
    return rep


def measured_report(rig, shot, truth: Report) -> Report:
    """The scope records through the pipeline, with beta and F_0 from the truth."""
    beta = truth.beta if truth.beta is not None else 1.0
    return analyze_record(shot.scope, setup_for(rig, beta, midway_static_force(rig)))


def theory_block(rig, truth: Report) -> dict:
    """Eq (2) at F_0, and Eq (1) at the truth's total force (m/s)."""
    bead = rig.chain.beads[min(g.bead for g in rig.gauges)]
    m = bead.material
    F0 = midway_static_force(rig)
    out = {"sound_speed_m_per_s": float(sound_speed(m.E, m.nu, m.rho, bead.diameter, F0)),
           "speed_m_per_s": None}
    if truth.amplitude_N and truth.amplitude_N > 0:
        out["speed_m_per_s"] = float(solitary_wave_speed(m.E, m.nu, m.rho, bead.diameter,
                                                         F0, F0 + truth.amplitude_N))
    return out


def shot_blocks(rig, shot) -> dict:
    """{"truth", "measured", "theory"} for `rig shot --json` (None without two gauges).
    truth and measured give "reasons" ({figure: why it is missing}, a dict, never null)
    and "flags" ({figure: why the figure given cannot be trusted as it is}: a leading pulse
    resolved by too few solver samples, coarse_sampling)."""
    if len(rig.gauges) < 2:
        return {"truth": None, "measured": None, "theory": None}
    truth = rig.truth_analysis()
    measured = measured_report(rig, shot, truth)
    keys = ("speed_m_per_s", "amplitude_N", "averaged_amplitude_N", "beta", "static_force_N",
            "pulses", "duration_s")
    def pick(r):
        return {k: _clean(getattr(r, k)) for k in keys}
    m = pick(measured)
    m["speed_xcorr_m_per_s"] = _clean(measured.speed_xcorr_m_per_s)
    m["reasons"] = dict(measured.reasons)  # why each missing figure is missing
    short = short_record(rig, truth)
    if short and m["speed_m_per_s"] is None:  # the root cause, named by its settings
        m["reasons"] = {figure: short for figure in m["reasons"]}
    t = pick(truth)
    t["reasons"] = dict(truth.reasons)  # a dict, never null: each missing figure has its reason
    for k in keys:  # a figure derived from one the pipeline left out (beta from F_d): the same reason
        if t[k] is None and k not in t["reasons"]:
            t["reasons"][k] = t["reasons"].get("amplitude_N") or t["reasons"].get("speed_m_per_s") or \
                "the truth's leading pulse was not found at both gauge beads"
    coarse = coarse_sampling(rig, truth)
    for block in (t, m):  # a figure given but not to be trusted as it is: {figure: why}
        block["flags"] = {k: coarse for k in SAMPLED_FIGURES if coarse and block.get(k) is not None}
    return {"truth": t, "measured": m, "theory": theory_block(rig, truth)}


SAMPLES_PER_WIDTH = 10
"""The fewest solver samples (solver.sample_interval) across the leading pulse's full width
at half maximum that its figures stand on. A sech^2 pulse (the solitary wave's shape) of
FWHM w sampled every h peaks in its samples at sech^2(h / 2 tau) of its true peak at worst
(w = 1.763 tau): N = w / h samples per width lose at worst 0.8 % of the peak at N = 10, 1.2 %
at 8, 3.0 % at 5, 8.2 % at 3, 17 % at 2 and 50 % at 1 (0.26 %, 0.4 %, 1.0 %, 2.8 %, 6 % and
20 % averaged over where the samples fall). Below 10 the amplitude, beta, width and peak
times are flagged; a PTFE pulse of 62 us at solver.sample_interval = 20 us (N = 3) measured
F_d 9 % low."""

SAMPLED_FIGURES = ("speed_m_per_s", "amplitude_N", "averaged_amplitude_N", "beta", "duration_s")


def coarse_sampling(rig, truth: Report) -> str | None:
    """Why the figures of a shot stand on too few solver samples across the leading pulse
    (fewer than SAMPLES_PER_WIDTH per FWHM), naming solver.sample_interval and the pulse's
    width; None where the pulse is resolved or has no width (the truth's own reasons then
    say why). A solver.sample_interval coarser than the scope's is refused before solving
    (Assembly.check_record)."""
    h = rig.solver.sample_interval
    widths = [lead["fwhm"] for lead in (truth.leading or {}).values()
              if isinstance(lead, dict) and math.isfinite(lead.get("fwhm", math.nan)) and lead["fwhm"] > 0]
    if not widths or min(widths) >= SAMPLES_PER_WIDTH * h:
        return None
    w = min(widths)
    return (f"solver.sample_interval = {h:g} s gives {w / h:.1f} samples across the leading pulse's {w:.3g} s "
            f"width (FWHM; fewer than {SAMPLES_PER_WIDTH} cut its peak by up to {100 * peak_loss(w / h):.0f} %): "
            f"a solver.sample_interval of at most {w / SAMPLES_PER_WIDTH:.2g} s")


def peak_loss(samples_per_width: float) -> float:
    """The largest share of a sech^2 pulse's peak lost by sampling it ``samples_per_width``
    times per FWHM (see SAMPLES_PER_WIDTH)."""
    half_step = math.acosh(math.sqrt(2)) / samples_per_width  # h / (2 tau), with FWHM = 2 tau acosh(sqrt 2)
    return 1 - 1 / math.cosh(half_step) ** 2


def short_record(rig, truth: Report) -> str | None:
    """Why no measured speed can come from a scope record shorter than the truth's pulse
    takes from the upper gauge to the lower (s), naming the settings; None otherwise."""
    setup = setup_for(rig)
    if not truth.speed_m_per_s:
        return None
    travel = (setup.lower.position_m - setup.upper.position_m) / truth.speed_m_per_s
    tb = rig.scope.timebase
    span = tb.record_length * tb.sample_interval
    if span >= travel:
        return None
    return (f"the scope record spans {span:.3g} s (scope.record_length = {tb.record_length} x scope.sample_interval "
            f"= {tb.sample_interval:g} s), shorter than the pulse's {travel:.3g} s from gauge to gauge")


def _clean(v):
    return None if v is None or (isinstance(v, float) and not math.isfinite(v)) else v
