"""The front panel's settings of the emulated oscilloscope (instruments.devices.oscilloscope),
each checked when made, with its unit: a channel's vertical settings, the time base, the
edge trigger; the ADC's codes per division (25, Tektronix); how a scope prints a figure per
division (WFID).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from ..errors import InstrumentError, check

CHANNELS = ("CH1", "CH2", "CH3", "CH4")
LEVEL_LIMIT_V = 1000.0  # the largest trigger level either way (V)
CODES_PER_DIV = 25.0


@dataclass(frozen=True)
class ChannelSettings:
    """volts_per_div (V/div at the probe tip), position (div), offset (V), coupling
    ("DC" | "AC"), bandwidth (Hz, None = full), probe (attenuation, x1 or more)."""

    volts_per_div: float = 0.1
    position: float = 0.0
    offset: float = 0.0
    coupling: str = "DC"
    bandwidth: float | None = 20e6
    probe: float = 1.0

    def __post_init__(self):
        check("scope.channels.CHn.volts_per_div", self.volts_per_div, lo=1e-3 * 0.999, hi=10.0 * 1.001,
              lo_closed=True, unit="V/div")
        check("scope.channels.CHn.position", self.position, lo=-5, hi=5, lo_closed=True, unit="div")
        check("scope.channels.CHn.offset", self.offset, lo=-100, hi=100, lo_closed=True, unit="V")
        check("scope.channels.CHn.coupling", self.coupling, choices=("DC", "AC"))
        if self.bandwidth is not None:
            check("scope.channels.CHn.bandwidth", self.bandwidth, lo=0, unit="Hz")
        check("scope.channels.CHn.probe", self.probe, lo=1, hi=1000, lo_closed=True)

    @property
    def y_multiplier(self) -> float:
        """Volts (at the probe tip) per ADC code: V/div / 25."""
        return self.volts_per_div / CODES_PER_DIV


@dataclass(frozen=True)
class Timebase:
    """sample_interval (s), record_length (points)."""

    sample_interval: float = 1e-7
    record_length: int = 20000

    def __post_init__(self):
        check("scope.sample_interval", self.sample_interval, lo=0, hi=1.0, unit="s")
        check("scope.record_length", self.record_length, lo=1, hi=10_000_000, lo_closed=False)
        if int(self.record_length) != self.record_length:
            raise InstrumentError(f"scope.record_length = {self.record_length!r}: a whole number of points")


@dataclass(frozen=True)
class Trigger:
    """Edge trigger: source channel, level (V), slope ("rising" | "falling"),
    pre_trigger (fraction of the record before the trigger, 0..1), mode ("normal" |
    "auto", the manuals' TRIGger:A:MODe NORMal | AUTO).

    NORMal waits for a valid trigger event: a shot whose input never crosses the level
    gives no record. AUTO "generates a trigger if one is not detected within a specified
    time period" (the 4 Series and MDO3000 manuals, TRIGger:A:MODe): a shot that does not
    trigger still gives a record, untriggered. A real scope's auto trigger fires when its
    timer runs out, at a time unrelated to the signal; here it is put at the impact
    (t = 0 of the input), so that the record is reproducible, shows the input at rest
    before the impact (its pre-trigger share, read at rest where it lies before the input)
    and what the shot did after it, and lies within the solved input wherever a triggered
    record of the same settings could (its trigger crossing is never before the impact).
    A shot that triggers gives the same record in either mode."""

    source: str = "CH1"
    level: float = 0.05
    slope: str = "rising"
    pre_trigger: float = 0.1
    mode: str = "normal"

    def __post_init__(self):
        check("scope.trigger.source", self.source, choices=CHANNELS)
        check("scope.trigger.level", self.level, lo=-LEVEL_LIMIT_V, hi=LEVEL_LIMIT_V, unit="V")
        check("scope.trigger.slope", self.slope, choices=("rising", "falling"))
        check("scope.trigger.pre_trigger", self.pre_trigger, lo=0, hi=1, lo_closed=True, hi_closed=False)
        check("scope.trigger.mode", self.mode, choices=("normal", "auto"))


def per_division(x: float, unit: str, digits: int = 4) -> str:
    """A V/div or s/div figure as a scope's WFID prints it, with an SI prefix and ``digits``
    significant digits (4 on the DPO/MDO/MSO, 3 on the TDS): 0.05 V -> ``50.00mV``, 2.5e-4 s
    -> ``250.0us``, 1 V -> ``1.000V``."""
    prefixes = {-12: "p", -9: "n", -6: "u", -3: "m", 0: "", 3: "k"}
    exp = min(max(3 * math.floor(math.log10(abs(x)) / 3), -12), 3) if x else 0
    return f"{x / 10 ** exp:#.{digits}g}".rstrip(".") + prefixes[exp] + unit
