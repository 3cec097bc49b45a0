"""Samples at the ADC's rail: how a record read from a file says that its signal ran off
the scope's range, since no scope file carries an over-range flag.

- Codes (ISF, WFM, the virtual scope): an 8-bit record clips at -128 and 127. A 16-bit
  record of an 8-bit converter holds the code times 256 (the low byte zero), so it clips at
  -32768 and 127 x 256 = 32512; a 16-bit record with other low bytes (averaged, or a 16-bit
  converter) clips at -32768 and 32767.
- Volts (CSV): a run of at least RUN consecutive samples equal to the record's maximum (or
  minimum) that lies at the screen's top (bottom) edge, where the header gives the vertical
  scale (V/div), offset (V) and position (div). Tektronix scopes put 25 codes in a division
  and the 8-bit rails 5.08 and -5.12 divisions from the centre; a value within EDGE_DIV of
  the centre is on screen, so a flat top there is a plateau of the signal, not the rail.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

RUN = 3  # equal samples in a row at the screen's edge: a clipped top (volts only)
EDGE_DIV = 4.95  # divisions from the screen's centre beyond which a value is at the rail
EIGHT_BIT_STEP = 256  # a 16-bit code of an 8-bit converter is a multiple of this


@dataclass(frozen=True)
class Rail:
    """A record's samples at the converter's rails: how many at the top and at the bottom,
    and the longest run of consecutive rail samples (samples; the flat top's length)."""

    top: int = 0
    bottom: int = 0
    longest_run: int = 0

    @property
    def clipped(self) -> bool:
        return self.top + self.bottom > 0

    def describe(self) -> str:
        """'351 samples at the ADC's top' (and/or bottom)."""
        parts = [f"{n} samples at the ADC's {where}" for n, where in ((self.top, "top"), (self.bottom, "bottom")) if n]
        return " and ".join(parts)


def code_rails(codes: np.ndarray) -> tuple:
    """(lowest, highest) code of the converter that wrote ``codes`` (int8 or int16)."""
    if codes.dtype.itemsize == 1:
        return -128, 127
    eight_bit = not np.any(codes.astype(np.int64) % EIGHT_BIT_STEP)
    return -32768, (127 * EIGHT_BIT_STEP if eight_bit else 32767)


def rail_of_codes(codes: np.ndarray) -> Rail:
    """The samples of an integer record at its converter's rails (code_rails)."""
    lo, hi = code_rails(codes)
    if lo < codes.min() and codes.max() < hi:
        return Rail()  # on screen: most records, in one pass
    return _rail(codes >= hi, codes <= lo)


def rail_of_volts(v: np.ndarray, volts_per_div: float, offset_V: float, position_div: float) -> Rail:
    """The samples of a volts record (a CSV) at the screen's edge: runs of at least RUN
    samples equal to the record's maximum (minimum) where that value lies EDGE_DIV or more
    divisions above (below) the centre; the screen's division of V is
    (V - offset) / (V/div) + position (Tektronix 4/5/6 Series, DPO, TBS1000C)."""
    v = np.asarray(v, dtype=float)
    if not (v.size and np.isfinite(volts_per_div) and volts_per_div > 0):
        return Rail()
    def div(x):
        return (x - offset_V) / volts_per_div + position_div
    hi, lo = float(np.max(v)), float(np.min(v))
    top = _long_runs(v == hi) if div(hi) >= EDGE_DIV else np.zeros(v.size, bool)
    bottom = _long_runs(v == lo) if div(lo) <= -EDGE_DIV else np.zeros(v.size, bool)
    return _rail(top, bottom)


def _long_runs(mask: np.ndarray) -> np.ndarray:
    """mask with its runs shorter than RUN cleared."""
    out = np.zeros(mask.size, bool)
    for start, stop in _runs(mask):
        if stop - start >= RUN:
            out[start:stop] = True
    return out


def _runs(mask: np.ndarray) -> list:
    """(start, stop) of every run of True in mask."""
    edges = np.flatnonzero(np.diff(np.concatenate(([0], mask.astype(np.int8), [0]))))
    return list(zip(edges[::2], edges[1::2]))


def _rail(top: np.ndarray, bottom: np.ndarray) -> Rail:
    longest = max((b - a for a, b in _runs(top | bottom)), default=0)
    return Rail(int(np.count_nonzero(top)), int(np.count_nonzero(bottom)), int(longest))


def rail(w) -> Rail:
    """The samples of a Waveform at its converter's rails: from its codes, or for volts
    (a CSV) from the screen the preamble's extra gives (volts_per_div, position_div,
    vertical_offset_V; no screen given: none can be told)."""
    if w.codes is not None:
        return rail_of_codes(np.asarray(w.codes))
    e = w.preamble.extra
    if e.get("volts_per_div") in (None, ""):
        return Rail()
    return rail_of_volts(w.samples, float(e["volts_per_div"]), float(e.get("vertical_offset_V", w.preamble.y_zero)),
                         float(e.get("position_div", 0.0)))


def flagged(w):
    """``w`` with its over-range flag set where its samples sit at the rail (rail): a
    record read from a file carries the flag the virtual scope sets when it clips."""
    return w if w.overrange or not rail(w).clipped else replace(w, overrange=True)


@dataclass(frozen=True)
class Clip:
    """A gauge channel that ran off the scope's range: why, in one phrase ('CH1: clipped:
    351 samples at the ADC's top, a flat top of 179 samples (3.58e-05 s)'), and how long
    its longest flat top lasts (s; nan where only the scope's flag says so)."""

    channel: str
    reason: str
    flat_top_s: float


def clipping(channel: str, at: Rail, dx: float, overrange: bool = False) -> Clip | None:
    """The Clip of a channel whose samples ``at`` sit at the rail (``dx``: the sample
    interval, s), or that the scope flagged (``overrange``); None where it is on screen."""
    if not at.clipped:
        return Clip(channel, f"{channel}: clipped", float("nan")) if overrange else None
    flat = at.longest_run * dx
    return Clip(channel, f"{channel}: clipped: {at.describe()}, a flat top of {at.longest_run} samples ({flat:.3g} s)",
                flat)
