"""What the scope does to a pulse that no figure may hide: its rails (a clipped top), its
bandwidth limit (a pulse lowered, widened and delayed) and the end of its record (a pulse
cut). The judge (instruments/analysis/judge.py) asks these rules of every record, real or
virtual, before it gives a figure."""
from __future__ import annotations

import math

import numpy as np

from .pulse import PeakRules
from .report import FIGURES, Report

CLIPPED_FIGURES = ("averaged_amplitude_N", "amplitude_N", "total_force_N", "duration_s", "base_duration_s",
                   "width_diameters")
# The most a flat top may move the speed: each peak time is uncertain by half its channel's
# flat top (the parabola through a plateau finds its middle, which is the peak's time only for
# a symmetric pulse), and the sum over the time of flight must stay below this.
CLIPPED_SPEED = 0.01


def with_clipping(rep: Report, clipped: tuple) -> Report:
    """``rep`` with what clipped channels (rails.Clip) allow: no amplitude or width (the
    pulses' tops are cut), and the speed figures only where the flat tops leave the peak
    times certain to CLIPPED_SPEED of the flight time; each reason names the samples at
    the rail, and where no figure is left, all share one reason."""
    if not clipped:
        return rep
    cut = (f"{'; '.join(c.reason for c in clipped)}: the signal ran off the scope's range, which cuts the pulses' "
           f"tops (a larger volts_per_div keeps them on screen)")
    if rep.speed_m_per_s is None:  # refused already: the clipping first
        for name in FIGURES:
            setattr(rep, name, None)
            rep.reasons[name] = f"{cut}; {rep.reasons[name]}" if name in rep.reasons else cut
        return rep
    flight = rep.leading["lower"]["time"] - rep.leading["upper"]["time"]
    doubt = flat_top_doubt(clipped)
    if speed_survives(doubt, flight):
        for name in CLIPPED_FIGURES:
            setattr(rep, name, None)
            rep.reasons[name] = cut
        return rep
    said = (f"the flat tops leave the peak times uncertain by up to {doubt:.3g} s, {100 * doubt / flight:.2g}% of the "
            f"{flight:.3g} s between the gauges" if math.isfinite(doubt)  # nan: a flag without the samples
            else "a flat top leaves the peak time uncertain")
    for name in FIGURES:
        setattr(rep, name, None)
        rep.reasons[name] = f"{cut}, and {said}"
    return rep


def flat_top_doubt(clipped: tuple) -> float:
    """How uncertain clipped channels (rails.Clip) leave the time of flight (s): half of
    each one's flat top, summed (nan where a flag comes without its samples)."""
    return 0.5 * sum(c.flat_top_s for c in clipped)


def speed_survives(doubt_s: float, flight_s: float) -> bool:
    """Whether the speed figures stand a flat-top uncertainty of ``doubt_s`` (s) on a time of
    flight ``flight_s`` (s): at most CLIPPED_SPEED of it."""
    return doubt_s <= CLIPPED_SPEED * flight_s


RISE_PER_BANDWIDTH = 0.35  # a one-pole filter's 10-90% rise time x its -3 dB bandwidth
# The most rise time per pulse FWHM: a Gaussian pulse through a one-pole filter whose rise
# time is 1/3 of its FWHM comes out 5% lower and 5% wider, its peak 0.14 FWHM late; at 1/2
# 10% and 10%, at 1 23% and 25% (numerical convolution). 5% is the amplitude's own error
# budget; beyond it the filter, not the chain, sets the pulse.
SLOW_FRACTION = 1 / 3


def slow(bandwidth_Hz, fwhm):
    """Whether a bandwidth limit ``bandwidth_Hz`` (Hz; 0: none known) distorts a pulse of
    FWHM ``fwhm`` (s; nan: none measured): its rise time RISE_PER_BANDWIDTH / bandwidth
    beyond SLOW_FRACTION of the FWHM. Arrays (or floats) broadcast together."""
    with np.errstate(divide="ignore", invalid="ignore"):
        rise = RISE_PER_BANDWIDTH / np.asarray(bandwidth_Hz, dtype=float)
        return (np.asarray(bandwidth_Hz) != 0) & np.isfinite(fwhm) & ~(rise <= SLOW_FRACTION * np.asarray(fwhm))


def too_slow(channel: str, bandwidth_Hz: float | None, fwhm: float) -> str:
    """Why a channel's bandwidth limit distorts its pulse of FWHM ``fwhm`` (s; slow); ''
    otherwise (no limit known, or no FWHM measured)."""
    if bandwidth_Hz is None or not slow(bandwidth_Hz, fwhm):
        return ""
    return (f"{channel}: its bandwidth limit of {bandwidth_Hz:.6g} Hz rises in 0.35/B = "
            f"{RISE_PER_BANDWIDTH / bandwidth_Hz:.3g} s, more than 1/3 of the measured pulse's FWHM ({fwhm:.3g} s): "
            f"the filter lowers, widens and delays the pulse (5% at 1/3); a wider bandwidth "
            f"(scope.channels.{channel}.bandwidth) or none")


END_SAMPLES = 3  # the last samples that show a pulse still rising at the record's end


def record_ends_in_pulse(f: np.ndarray | None, sigma: float | None, rules: PeakRules) -> bool:
    """Whether a conditioned record ``f`` (baseline 0) ends inside its largest pulse: its
    maximum among its last END_SAMPLES samples (still rising), or its last sample above
    half its maximum (the pulse's fall cut), the maximum standing ``rules.snr`` noise
    levels above the baseline where the noise ``sigma`` is known. False without a record."""
    if f is None or f.size <= END_SAMPLES:
        return False
    peak = float(np.max(f))
    if not peak > 0 or (sigma is not None and peak < rules.snr * sigma):
        return False
    return int(np.argmax(f)) >= f.size - END_SAMPLES or float(f[-1]) >= 0.5 * peak
