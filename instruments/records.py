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
            assert self.samples is not None, f"channel {self.channel}: every reader gives codes or volts"
            return self.samples
        p = self.preamble
        return p.y_zero + p.y_multiplier * (self.codes.astype(np.float64) - p.y_offset)

    def time(self) -> np.ndarray:
        p = self.preamble
        return p.x_zero + p.x_increment * np.arange(p.points)

    def envelope(self) -> tuple:
        """(t, v_min, v_max) of an envelope record (``point_format == "ENV"``), volts.

        Tektronix scopes send an envelope as (min, max) pairs, NR_PT counting values and
        XINCR the interval between values, so that pair k covers the samples 2k and 2k+1
        (a 10-division screen holds NR_PT x XINCR). The order within a pair differs
        between models, so each pair's smaller value is the minimum; t is the middle of
        the pair's interval (s from the trigger)."""
        if self.preamble.point_format != "ENV":
            raise ValueError(f"{self.channel}: not an envelope record (point format {self.preamble.point_format!r})")
        v = self.volts()
        pairs = v[: v.size - v.size % 2].reshape(-1, 2)
        t = self.preamble.x_zero + self.preamble.x_increment * (2 * np.arange(pairs.shape[0]) + 0.5)
        return t, pairs.min(axis=1), pairs.max(axis=1)


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


SAME_TIME = 1e-6  # samples: two channels whose sample times differ less than this share one time base


def time_base_mismatch(a: Waveform, b: Waveform) -> str | None:
    """None where ``a`` and ``b`` share one time base (the same points, and every sample
    time within SAME_TIME of a sample of each other: a CSV prints times a binary file holds
    exactly); otherwise one line naming both records (their source files, where read from
    files) and their time bases."""
    pa, pb = a.preamble, b.preamble
    dt = min(pa.x_increment, pb.x_increment)
    drift = abs(pa.x_zero - pb.x_zero) + abs(pa.x_increment - pb.x_increment) * max(pa.points - 1, 0)
    if pa.points == pb.points and drift <= SAME_TIME * dt:
        return None
    return (f"{_origin(a)} and {_origin(b)} have different time bases: {_said(a)}, {_said(b)} "
            f"(first samples {pb.x_zero - pa.x_zero:.3g} s apart); the channels of one shot share one time base")


def _origin(w: Waveform) -> str:
    source = w.preamble.extra.get("source")
    return f"{source} ({w.channel})" if source else f"channel {w.channel}"


def _said(w: Waveform) -> str:
    p = w.preamble
    return f"{p.points} points at {p.x_increment:.10g} s from {p.x_zero:.10g} s"
