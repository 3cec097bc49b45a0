"""The record types every scope-side module shares: what a real Tektronix scope returns.

A Waveform is one channel: integer ADC codes plus the preamble that scales them
(Tektronix WFMPRE convention), volts = y_zero + y_multiplier * (code - y_offset) and
t = x_zero + x_increment * n with x_zero the time of the first sample relative to the
trigger (s). Records read from files that hold volts only (CSV) carry ``codes = None``.
An envelope (peak-detect) record, ``point_format == "ENV"``, holds (min, max) pairs: its
samples alternate between the minimum and the maximum of each acquisition interval.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True)
class Preamble:
    """Scaling and timing of a record (SI: s, V)."""

    points: int
    x_increment: float
    x_zero: float
    trigger_index: int
    y_multiplier: float
    y_offset: float
    y_zero: float
    byte_count: int = 1
    x_unit: str = "s"
    y_unit: str = "V"
    waveform_id: str = ""
    point_format: str = "Y"  # "Y": one sample per point; "ENV": envelope, (min, max) pairs
    extra: dict = field(default_factory=dict)


@dataclass(frozen=True, eq=False)
class Waveform:
    """One channel's record: codes (int8/int16) or volts, preamble, over-range flag."""

    channel: str
    preamble: Preamble
    codes: np.ndarray | None = None
    samples: np.ndarray | None = None  # volts, where no codes exist (CSV files)
    overrange: bool = False

    def volts(self) -> np.ndarray:
        if self.codes is None:
            return self.samples
        p = self.preamble
        return p.y_zero + p.y_multiplier * (self.codes.astype(np.float64) - p.y_offset)

    def time(self) -> np.ndarray:
        p = self.preamble
        return p.x_zero + p.x_increment * np.arange(p.points)


@dataclass(frozen=True, eq=False)
class ScopeRecord:
    """One acquisition of a scope: a waveform per displayed channel, or why it did not
    trigger (``triggered`` False, ``reason`` says why, ``waveforms`` empty)."""

    waveforms: dict
    triggered: bool
    reason: str | None = None
    trigger_time: float | None = None  # on the signal's own clock (s), for ground truth

    def __getitem__(self, channel: str) -> Waveform:
        return self.waveforms[channel]
