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


def record_doubt(limits: Limits, distance_m: float, span_s: float) -> str | None:
    """Why a record of ``span_s`` (s) cannot hold a pulse crossing ``distance_m`` (m), or None."""
    need = distance_m / limits.max_speed_m_per_s
    if need > span_s:
        return (f"the gauges are {distance_m:.4g} m apart: even at {limits.max_speed_m_per_s:.4g} m/s a pulse "
                f"needs {need:.3g} s between them, but the record spans {span_s:.3g} s (is the gauge distance right?)")
    return None


def speed_doubt(limits: Limits, distance_m: float, flight_s: float, h_s: float, fwhm_s: float,
                diameter_m: float) -> str | None:
    """Why the speed distance / flight is not a chain's (each check above), or None.
    h_s: sample interval (s); fwhm_s: the leading pulse's FWHM (s; nan: not checked)."""
    speed = distance_m / flight_s
    said = f"{speed:.4g} m/s ({distance_m * 1e3:.4g} mm in {flight_s * 1e6:.4g} us)"
    if flight_s < limits.min_flight_samples * h_s:
        return (f"the time of flight is {flight_s / h_s:.2g} samples, under the {limits.min_flight_samples:g} "
                f"needed for a speed to 10%: {said} is not measured")
    if speed > limits.max_speed_m_per_s:
        return (f"{said} is faster than {limits.max_speed_m_per_s:.4g} m/s, "
                "which no solitary wave of a bead chain reaches")
    width = fwhm_s * speed / diameter_m
    lo, hi = limits.width_diameters
    if math.isfinite(width) and not lo <= width <= hi:
        return (f"at {said} the leading pulse's FWHM is {width:.3g} bead diameters, outside the "
                f"{lo:g} to {hi:g} of a solitary wave")
    return None
