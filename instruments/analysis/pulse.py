"""What a pulse is and which maxima are pulses: ``Pulse`` (time, amplitude, widths; s and
the signal's unit) and ``PeakRules`` (the rules of scipy.signal.find_peaks, a pulse's top
for its parabola, the leading pulse, the SNR rule). Every stage below reads them."""
from __future__ import annotations

import math
from dataclasses import dataclass

from ..errors import check


@dataclass(frozen=True)
class PeakRules:
    """Which maxima are pulses. height, prominence: fractions of the record's maximum;
    distance: least spacing of pulses (s); width: least width of a pulse at half its
    prominence (s; rejects noise spikes, which are a sample or two wide); top: fraction of a
    pulse's amplitude over which its parabola is fitted; lead: the leading pulse is the
    first one above this fraction of the record's largest pulse; snr: where the noise is
    known, a pulse must stand this many noise levels above the baseline. 8: a record of
    1e7 Gaussian samples exceeds 6.4 sigma about once in a thousand records
    (1e7 x Q(6.4) = 8e-4), and the margin to 8 covers the MAD's own scatter on a short
    baseline and noise tails heavier than Gaussian."""

    height: float = 0.1
    prominence: float = 0.05
    distance: float = 0.0
    width: float = 2e-6
    top: float = 0.05
    lead: float = 0.3
    snr: float = 8.0

    def as_tuple(self) -> tuple:
        """(height, prominence, top, lead, snr, distance, width): the compiled analysis' form."""
        return (float(self.height), float(self.prominence), float(self.top), float(self.lead), float(self.snr),
                float(self.distance), float(self.width))

    def __post_init__(self):
        check("peaks.snr", self.snr, lo=0, hi=math.inf, hi_closed=False)
        for name in ("height", "prominence", "top", "lead"):
            check(f"peaks.{name}", getattr(self, name), lo=0, hi=1)
        check("peaks.distance", self.distance, lo=0, lo_closed=True, unit="s")
        check("peaks.width", self.width, lo=0, lo_closed=True, unit="s")


# the default rules (a frozen instance, shared by every call that names none)
DEFAULT_RULES = PeakRules()


@dataclass(frozen=True)
class Pulse:
    """One pulse: time of its maximum (s), amplitude (same unit as the signal), full width
    at half maximum and at 1% of the amplitude, and rise from 1% to the maximum (s, nan
    where the signal never falls there). In a train the 1% width runs into the next pulse;
    twice the rise is then the pulse's own width."""

    time: float
    amplitude: float
    fwhm: float
    base_width: float
    rise: float = math.nan
