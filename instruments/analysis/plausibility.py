"""Is a measured speed one a granular chain can have? The checks need no simulator: only
the gauge distance, the record's sample interval and span, the leading pulse's FWHM and
the bead diameter, and a speed bound the caller may tighten with the bead material.

- Time of flight: at least ``min_flight_samples`` samples. With the peak times good to
  about half a sample, 5 samples keep the speed within the published 10%.
- Speed bound: a solitary wave in a chain of beads is far slower than the bar speed
  sqrt(E / rho) of the bead material (PTFE 815 m/s, steel 4.9 km/s); with the material
  unknown, 18 km/s (diamond, the fastest of solids) bounds any bead.
- Gauge distance against the record: at the bound, the pulse needs distance / bound to
  pass from one gauge to the other; a record shorter than that cannot hold both pulses.
- Width: a solitary wave is about five diameters long (Nesterenko); its FWHM is about 1.5
  diameters in the sonic vacuum, wider with precompression. A leading pulse whose FWHM
  times the speed is outside ``width_diameters`` is no wave of the chain.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import InstrumentError, check


@dataclass(frozen=True)
class Limits:
    """What a chain's speed may be: max_speed_m_per_s (the bound above), min_flight_samples
    (least time of flight, in samples), width_diameters (least and most FWHM of the leading
    pulse, in bead diameters)."""

    max_speed_m_per_s: float = 18000.0
    min_flight_samples: float = 5.0
    width_diameters: tuple = (0.5, 20.0)

    def __post_init__(self):
        check("limits.max_speed", self.max_speed_m_per_s, lo=0, hi=math.inf, hi_closed=False, unit="m/s")
        check("limits.min_flight_samples", self.min_flight_samples, lo=0, lo_closed=True, hi=math.inf,
              hi_closed=False)
        lo, hi = self.width_diameters
        if not 0 <= lo < hi:
            raise InstrumentError(f"limits.width_diameters = {self.width_diameters!r}: allowed 0 <= least < most")


# why a speed is not a chain's (doubts), in the order the checks run
NO_DOUBT, SHORT_RECORD, FEW_SAMPLES, TOO_FAST, WRONG_WIDTH = range(5)


def doubts(limits: Limits, distance_m: float, span_s, flight_s, h_s, fwhm_s, diameter_m: float) -> np.ndarray:
    """The first check each speed distance / flight fails (arrays, one entry per shot),
    NO_DOUBT where it passes them all: SHORT_RECORD, a record of ``span_s`` (s) too short
    for a pulse crossing ``distance_m`` (m) even at the speed bound; FEW_SAMPLES, a time of
    flight under ``min_flight_samples`` sample intervals ``h_s`` (s); TOO_FAST, a speed over
    the bound; WRONG_WIDTH, the leading pulse's FWHM ``fwhm_s`` (s; nan: not checked) times
    the speed outside ``width_diameters`` bead diameters ``diameter_m`` (m)."""
    lo, hi = limits.width_diameters
    with np.errstate(divide="ignore", invalid="ignore"):
        speed = distance_m / np.asarray(flight_s, dtype=float)
        width = fwhm_s * speed / diameter_m
        return np.select([distance_m / limits.max_speed_m_per_s > np.asarray(span_s),
                          flight_s < limits.min_flight_samples * np.asarray(h_s), speed > limits.max_speed_m_per_s,
                          np.isfinite(width) & ~((lo <= width) & (width <= hi))],
                         [SHORT_RECORD, FEW_SAMPLES, TOO_FAST, WRONG_WIDTH], NO_DOUBT)


def doubt_text(doubt: int, limits: Limits, distance_m: float, span_s: float, flight_s: float, h_s: float,
               fwhm_s: float, diameter_m: float) -> str:
    """What doubt ``doubt`` (doubts' code) says of one speed, with its numbers ('' for NO_DOUBT)."""
    speed = distance_m / flight_s if flight_s != 0 else math.inf
    said = f"{speed:.4g} m/s ({distance_m * 1e3:.4g} mm in {flight_s * 1e6:.4g} us)"
    if doubt == SHORT_RECORD:
        need = distance_m / limits.max_speed_m_per_s
        return (f"the gauges are {distance_m:.4g} m apart: even at {limits.max_speed_m_per_s:.4g} m/s a pulse "
                f"needs {need:.3g} s between them, but the record spans {span_s:.3g} s (is the gauge distance right?)")
    if doubt == FEW_SAMPLES:
        return (f"the time of flight is {flight_s / h_s:.2g} samples, under the {limits.min_flight_samples:g} "
                f"needed for a speed to 10%: {said} is not measured")
    if doubt == TOO_FAST:
        return (f"{said} is faster than {limits.max_speed_m_per_s:.4g} m/s, "
                "which no solitary wave of a bead chain reaches")
    if doubt == WRONG_WIDTH:
        lo, hi = limits.width_diameters
        return (f"at {said} the leading pulse's FWHM is {fwhm_s * speed / diameter_m:.3g} bead diameters, outside "
                f"the {lo:g} to {hi:g} of a solitary wave")
    return ""
