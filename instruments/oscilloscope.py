"""A 4-channel Tektronix-style digital oscilloscope, emulated.

Per channel: V/div, vertical position (div), offset (V), DC/AC coupling, bandwidth limit,
probe attenuation. Horizontal: sample interval and record length. Edge trigger on one
channel (level, slope, pre-trigger fraction) with a random sub-sample phase of the
sampling clock. 8-bit ADC, 25 codes per division (Tektronix), codes clipped to
[-128, 127] with an over-range flag. Sample or average-N acquisition (averaging the
scope's own noise over N acquisitions of the same input). A channel with no input reads
the scope's noise floor.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ._kernels.quantiser import quantise
from ._kernels.resample import at_positions
from .errors import InstrumentError, check
from .frontend import lowpass, rc_highpass
from .records import Preamble, ScopeRecord, Waveform

CHANNELS = ("CH1", "CH2", "CH3", "CH4")
CODES_PER_DIV = 25.0
CODE_MIN, CODE_MAX = -128, 127
AC_CORNER_HZ = 10.0  # AC coupling's high-pass corner


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
        check("scope.channel.volts_per_div", self.volts_per_div, lo=1e-3 * 0.999, hi=10.0 * 1.001,
              lo_closed=True, unit="V/div")
        check("scope.channel.position", self.position, lo=-5, hi=5, lo_closed=True, unit="div")
        check("scope.channel.offset", self.offset, lo=-100, hi=100, lo_closed=True, unit="V")
        check("scope.channel.coupling", self.coupling, choices=("DC", "AC"))
        if self.bandwidth is not None:
            check("scope.channel.bandwidth", self.bandwidth, lo=0, unit="Hz")
        check("scope.channel.probe", self.probe, lo=1, hi=1000, lo_closed=True)

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
    pre_trigger (fraction of the record before the trigger, 0..1)."""

    source: str = "CH1"
    level: float = 0.05
    slope: str = "rising"
    pre_trigger: float = 0.1

    def __post_init__(self):
        check("scope.trigger.source", self.source, choices=CHANNELS)
        check("scope.trigger.level", self.level, lo=-1000, hi=1000, unit="V")
        check("scope.trigger.slope", self.slope, choices=("rising", "falling"))
        check("scope.trigger.pre_trigger", self.pre_trigger, lo=0, hi=1, lo_closed=True, hi_closed=False)


@dataclass(frozen=True)
class Oscilloscope:
    """The scope's front panel; ``acquire`` turns analog inputs into a ScopeRecord.

    channels: displayed channels {"CH1": ChannelSettings, ...}; noise_floor: the scope's
    own input noise (V rms at the input connector); mode "sample" | "average", averages N.
    """

    channels: dict = field(default_factory=lambda: {"CH1": ChannelSettings()})
    timebase: Timebase = Timebase()
    trigger: Trigger = Trigger()
    mode: str = "sample"
    averages: int = 1
    noise_floor: float = 2e-4
    model: str = "TDS2024C"

    def __post_init__(self):
        for name in self.channels:
            check("scope.channels", name, choices=CHANNELS)
        if not self.channels:
            raise InstrumentError("scope.channels = {}: display at least one channel")
        if self.trigger.source not in self.channels:
            raise InstrumentError(f"scope.trigger.source = {self.trigger.source!r}: the trigger "
                                  f"channel must be displayed (displayed: {', '.join(self.channels)})")
        check("scope.mode", self.mode, choices=("sample", "average"))
        check("scope.averages", self.averages, lo=1, hi=512, lo_closed=True)
        if self.mode == "sample" and self.averages != 1:
            raise InstrumentError(f"scope.averages = {self.averages}: only 1 in sample mode")
        check("scope.noise_floor", self.noise_floor, lo=0, lo_closed=True, unit="V")

    # --- acquisition ----------------------------------------------------------------
    def acquire(self, inputs: dict, h: float, rng: np.random.Generator) -> ScopeRecord:
        """Acquire one record.

        inputs: {channel: volts at the probe tip}, sampled every h seconds from t = 0; before
        t = 0 each input is held at its first value. Displayed channels without an input
        read noise. Returns a ScopeRecord; a record that does not trigger says so.
        """
        n_in = max((len(v) for v in inputs.values()), default=0)
        analog = {ch: self._condition(np.asarray(inputs.get(ch, np.zeros(n_in)), float), s, h)
                  for ch, s in self.channels.items()}
        tb, tr = self.timebase, self.trigger
        t_cross = _first_crossing(analog[tr.source], h, tr.level, tr.slope)
        if t_cross is None:
            return ScopeRecord({}, False, f"no {tr.slope} crossing of {tr.level:g} V on "
                                          f"{tr.source} in {n_in * h:.4g} s")
        n_pre = int(round(tr.pre_trigger * tb.record_length))
        phase = rng.uniform(0.0, tb.sample_interval)
        x_zero = phase - n_pre * tb.sample_interval  # first sample, relative to the trigger
        t = t_cross + x_zero + tb.sample_interval * np.arange(int(tb.record_length))
        t_end = (n_in - 1) * h
        if t[-1] > t_end * (1 + 1e-12):
            raise InstrumentError(
                f"scope record ends {t[-1]:.4g} s after t = 0 but the input stops at {t_end:.4g} s: "
                f"record a longer input or shorten the record")
        waves = {}
        for ch, s in self.channels.items():
            v = at_positions(analog[ch], t / h)  # linear between the input's samples
            waves[ch] = self._digitise(ch, s, v, x_zero, n_pre, rng)
        return ScopeRecord(waves, True, None, t_cross)

    def _condition(self, v, s: ChannelSettings, h: float):
        x = v / s.probe  # at the input connector
        if s.coupling == "AC":
            x = rc_highpass(x, h, 1.0 / (2 * math.pi * AC_CORNER_HZ))
        if s.bandwidth is not None:
            x = lowpass(x, h, s.bandwidth)
        return x * s.probe  # expressed back at the probe tip, as the scope displays it

    def _digitise(self, ch, s: ChannelSettings, v, x_zero, n_pre, rng) -> Waveform:
        ymult = s.y_multiplier
        yoff = s.position * CODES_PER_DIV
        sd, noise = 0.0, np.empty(0)
        if self.noise_floor:  # the mean of N acquisitions' noise: sd / sqrt(N)
            sd = self.noise_floor * s.probe / ymult / math.sqrt(self.averages)
            noise = rng.standard_normal(v.size)
        # codes = round((v - offset) / ymult + yoff + sd * noise), clipped to 8 bits
        codes, overrange = quantise(np.ascontiguousarray(v, dtype=float), float(s.offset), ymult, yoff, sd, noise,
                                    float(CODE_MIN), float(CODE_MAX))
        pre = Preamble(points=v.size, x_increment=self.timebase.sample_interval, x_zero=x_zero,
                       trigger_index=n_pre, y_multiplier=ymult, y_offset=yoff, y_zero=s.offset,
                       byte_count=1,
                       waveform_id=(f"{ch}, {s.coupling} coupling, {s.volts_per_div:g}V/div, "
                                    f"{self.timebase.sample_interval * v.size / 10:.4g}s/div, {v.size} points, "
                                    f"{'Sample' if self.mode == 'sample' else f'Average {self.averages}'} mode"),
                       extra={"volts_per_div": s.volts_per_div, "position_div": s.position,
                              "coupling": s.coupling, "bandwidth_Hz": s.bandwidth, "probe": s.probe,
                              "model": self.model})
        return Waveform(ch, pre, codes=codes, overrange=overrange)


def _first_crossing(x, h, level, slope):
    """Time (s) of the first crossing of ``level`` with ``slope``, linearly interpolated."""
    if slope == "rising":
        idx = np.flatnonzero((x[:-1] < level) & (x[1:] >= level))
    else:
        idx = np.flatnonzero((x[:-1] > level) & (x[1:] <= level))
    if idx.size == 0:
        return None
    i = idx[0]
    return (i + (level - x[i]) / (x[i + 1] - x[i])) * h
