"""A 4-channel Tektronix-style digital oscilloscope, emulated.

Per channel: V/div, vertical position (div), offset (V), DC/AC coupling, bandwidth limit,
probe attenuation. Horizontal: sample interval and record length. Edge trigger on one
channel (level, slope, pre-trigger fraction) with a random sub-sample phase of the
sampling clock, in NORMal mode (no trigger, no record) or AUTO (no trigger: a record taken
untriggered, its trigger point at the impact; ``Trigger``). 8-bit ADC, 25 codes per
division (Tektronix), codes clipped to [-128, 127] with an over-range flag. Sample or
average-N acquisition (averaging the scope's own noise over N acquisitions of the same
input). A channel with no input reads the scope's noise floor.
"""
from __future__ import annotations

import enum
import math
from dataclasses import dataclass, field

import numpy as np

from ..errors import InstrumentError, check
from ..records import Preamble, ScopeRecord, Waveform
from ._kernels import acquisition
from ._kernels.acquisition import TRIGGER_BAND_CODES, at_rest_before, condition, samples_before_input, scope_shot
from .frontend import highpass_coefficients, lowpass_coefficients
from .scope_settings import CHANNELS as CHANNELS  # the front panel's settings, also this module's names
from .scope_settings import CODES_PER_DIV
from .scope_settings import ChannelSettings as ChannelSettings
from .scope_settings import Timebase as Timebase
from .scope_settings import Trigger as Trigger
from .scope_settings import per_division as per_division

CODE_MIN, CODE_MAX = -128, 127
AC_CORNER_HZ = 10.0  # AC coupling's high-pass corner


class AcquisitionStatus(enum.IntEnum):
    """How an acquisition ended: the compiled acquisition's codes (_kernels/acquisition.py,
    plain ints there), named where they leave it."""

    OK = acquisition.OK
    NO_TRIGGER = acquisition.NO_TRIGGER
    PAST_INPUT = acquisition.PAST_INPUT  # the record would run past the input
    AUTO = acquisition.AUTO  # no trigger; taken untriggered in AUTO mode, its trigger point at the impact

    @property
    def message(self) -> str:
        return _ACQUISITION_MESSAGES[self]


_ACQUISITION_MESSAGES = {AcquisitionStatus.OK: "the scope triggered and its record lies within the input",
                         AcquisitionStatus.NO_TRIGGER: "the scope did not trigger",
                         AcquisitionStatus.PAST_INPUT: "the scope's record runs past the input",
                         AcquisitionStatus.AUTO: "the scope did not trigger; in AUTO mode it took the record "
                                                 "untriggered, its trigger point at the impact"}


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
    def acquire(self, inputs: dict, h: float, rng: np.random.Generator, rest: dict | None = None) -> ScopeRecord:
        """Acquire one record.

        inputs: {channel: volts at the probe tip}, sampled every h seconds from t = 0 (the
        impact). Before t = 0 each input is at rest: its noise ``rest[channel]`` (V rms; a
        gauge's noise) about its rest level, or, without noise, its first value held. Displayed
        channels without an input read noise. Returns a ScopeRecord; a record that does not
        trigger says so (in AUTO mode it is taken all the same, untriggered, its trigger
        point at the impact). Draws from rng the clock's phase, then each displayed
        channel's noise (shot_draws' order), then, only for a record that starts before
        t = 0, the rest noise of each input over the samples before it, in the order of the
        displayed channels. The conversions follow acquisition.shots' order, so a batch's
        shot has these bits.
        """
        tb = self.timebase
        phase = rng.uniform(0.0, tb.sample_interval)
        shape = (len(self.channels), int(tb.record_length) if self.noise_floor else 0)
        noise = rng.standard_normal(shape) if self.noise_floor else np.empty(shape)
        n_in = max((len(v) for v in inputs.values()), default=0)
        forced, n_pad, read = math.nan, 0, inputs
        for _ in range(3):  # the edge; in AUTO, none found: the impact; the record again from before the input
            status, t_cross, x_zero, codes, over = self._convert(read, h, phase, noise, forced + n_pad * h)
            if status == AcquisitionStatus.NO_TRIGGER and self.trigger.mode == "auto":
                forced = 0.0
                continue
            if n_pad:
                break
            n_pad = samples_before_input(int(status), t_cross, x_zero, h)  # an int: the kernel's one signature
            if not n_pad:
                break
            read = self._at_rest_before(inputs, rest or {}, n_pad, rng)
        t_cross -= n_pad * h
        return self.record_of(status, t_cross, x_zero, codes, over, n_in, h)

    def _at_rest_before(self, inputs: dict, rest: dict, n_pad: int, rng: np.random.Generator) -> dict:
        """The inputs with n_pad samples of rest before them (at_rest_before), each input's
        rest noise drawn in the order of the displayed channels."""
        padded = {}
        for ch in self.channels:
            if ch in inputs:
                sd = float(rest.get(ch, 0.0))
                z = rng.standard_normal(n_pad) if sd > 0 else np.zeros(n_pad)
                padded[ch] = at_rest_before(np.ascontiguousarray(inputs[ch], dtype=float), sd, z)
        return padded

    def _convert(self, inputs: dict, h: float, phase: float, noise: np.ndarray, forced: float = math.nan) -> tuple:
        """The trigger and the 8-bit conversion of inputs (every h s from their first sample)
        with the clock's phase and the scope's noise draws; ``forced`` (s from the first
        input sample): an AUTO record's trigger point, no edge looked for (nan: the edge's).
        Returns (status, time of the trigger point from the first input sample s, time of
        the first sample after it s, codes, over-range flags)."""
        front = self.front_panel(h)
        tb = self.timebase
        codes = np.empty((len(self.channels), int(tb.record_length)), np.int8)
        over = np.empty(len(self.channels), np.bool_)
        status, t_cross, x_zero = scope_shot(self.analog(inputs, h), float(h), front.source, front.level,
                                             front.rising, float(forced), phase, front.n_pre, tb.sample_interval,
                                             front.offset, front.ymult, front.yoff, front.sd, noise, float(CODE_MIN),
                                             float(CODE_MAX), codes, over, np.ones(len(self.channels), np.bool_))
        return AcquisitionStatus(status), t_cross, x_zero, codes, over

    def analog(self, inputs: dict, h: float) -> np.ndarray:
        """(channels, samples): each displayed channel's input (volts at the probe tip, every
        h s) after the front end (probe factor, AC coupling, bandwidth limit), before the
        noise and the 8-bit conversion; a channel without input reads 0."""
        n_in = max((len(v) for v in inputs.values()), default=0)
        front = self.front_panel(h)
        analog = np.empty((len(self.channels), n_in))
        for c, ch in enumerate(self.channels):
            v = np.ascontiguousarray(inputs[ch], dtype=float) if ch in inputs else np.zeros(n_in)
            analog[c] = condition(v, front.probe[c], front.ac[c], front.lowpass[c])
        return analog

    def record_of(self, status: int | AcquisitionStatus, t_cross: float, x_zero: float, codes, over, n_in: int,
                  h: float, read=None) -> ScopeRecord:
        """The ScopeRecord of one acquisition (acquisition.scope_shot's status and times,
        codes (channels, samples), over-range flags; read (channels,): the channels
        converted, None: all), or InstrumentError where the record would run past the input
        of n_in samples every h s."""
        tb, tr = self.timebase, self.trigger
        status = AcquisitionStatus(status)
        band = TRIGGER_BAND_CODES * self.channels[tr.source].y_multiplier
        no_edge = (f"no {tr.slope} crossing of {tr.level:g} V on {tr.source} in {n_in * h:.4g} s (past the "
                   f"trigger's noise band of {band:.3g} V: it fires where the signal goes {band / 2:.3g} V beyond "
                   f"the level)")
        if status is AcquisitionStatus.NO_TRIGGER:
            return ScopeRecord({}, False, no_edge)
        if status is AcquisitionStatus.PAST_INPUT:
            last = t_cross + x_zero + tb.sample_interval * (int(tb.record_length) - 1)
            raise InstrumentError(
                f"scope record ends {last:.4g} s after t = 0 but the input stops at {(n_in - 1) * h:.4g} s: "
                f"record a longer input or shorten the record")
        n_pre = int(round(tr.pre_trigger * tb.record_length))
        auto = status is AcquisitionStatus.AUTO
        waves = {ch: self._waveform(ch, s, codes[c], bool(over[c]), float(x_zero), n_pre, auto)
                 for c, (ch, s) in enumerate(self.channels.items()) if read is None or read[c]}
        if auto:  # untriggered: the record's time zero is the impact
            return ScopeRecord(waves, False, f"auto-triggered: {no_edge}; in AUTO mode the scope took the record "
                                             "untriggered, its trigger point at the impact", float(t_cross))
        return ScopeRecord(waves, True, None, float(t_cross))

    def front_panel(self, h: float) -> FrontPanel:
        """The settings of every displayed channel, the trigger and the converter as the
        compiled acquisition takes them, for inputs sampled every h s."""
        chans = list(self.channels.values())
        ac = np.full((len(chans), 3), np.nan)
        low = np.full((len(chans), 3), np.nan)
        for c, s in enumerate(chans):
            if s.coupling == "AC":
                ac[c] = highpass_coefficients(h, 1.0 / (2 * math.pi * AC_CORNER_HZ))
            if s.bandwidth is not None:
                low[c] = lowpass_coefficients(h, s.bandwidth)
        tb, tr = self.timebase, self.trigger
        ymult = np.array([s.y_multiplier for s in chans])
        probe = np.array([s.probe for s in chans], dtype=float)
        sd = (self.noise_floor * probe / ymult / math.sqrt(self.averages) if self.noise_floor
              else np.zeros(len(chans)))
        return FrontPanel(probe, ac, low, list(self.channels).index(tr.source), float(tr.level), tr.slope == "rising",
                          int(round(tr.pre_trigger * tb.record_length)),
                          np.array([float(s.offset) for s in chans]), ymult,
                          np.array([s.position * CODES_PER_DIV for s in chans]), sd, tr.mode == "auto")

    def _waveform(self, ch, s: ChannelSettings, codes, overrange: bool, x_zero: float, n_pre: int,
                  auto: bool = False) -> Waveform:
        """One channel's Waveform; an AUTO record's preamble says so (extra "auto_triggered")."""
        pre = Preamble(points=codes.size, x_increment=self.timebase.sample_interval, x_zero=x_zero,
                       trigger_index=n_pre, y_multiplier=s.y_multiplier, y_offset=s.position * CODES_PER_DIV,
                       y_zero=s.offset, byte_count=1,
                       waveform_id=(f"{ch}, {s.coupling} coupling, {per_division(s.volts_per_div, 'V')}/div, "
                                    f"{per_division(self.timebase.sample_interval * codes.size / 10, 's')}/div, "
                                    f"{codes.size} points, "
                                    f"{'Sample' if self.mode == 'sample' else f'Average {self.averages}'} mode"),
                       extra={"volts_per_div": s.volts_per_div, "position_div": s.position,
                              "coupling": s.coupling, "bandwidth_Hz": s.bandwidth, "probe": s.probe,
                              "model": self.model, **({"auto_triggered": True} if auto else {})})
        return Waveform(ch, pre, codes=codes, overrange=overrange)


@dataclass(frozen=True, eq=False)
class FrontPanel:
    """An oscilloscope's settings as arrays, one row per displayed channel (in display
    order): probe attenuation, AC coupling and bandwidth limit ((b0, b1, a1) one-pole
    coefficients, nan: off), the trigger (source channel index, level V, rising, pre-trigger
    samples), the converter (offset V, V per code, code offset, noise in codes) and the
    trigger's mode (auto: AUTO, a shot that does not trigger taken untriggered)."""

    probe: np.ndarray
    ac: np.ndarray
    lowpass: np.ndarray
    source: int
    level: float
    rising: bool
    n_pre: int
    offset: np.ndarray
    ymult: np.ndarray
    yoff: np.ndarray
    sd: np.ndarray
    auto: bool
