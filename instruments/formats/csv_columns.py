"""What a Tektronix CSV header promises of its columns, checked against them, every layout
alike: the TIME column's time base (``time_base``: the header's Sample Interval and Zero
Index against the column, as tightly as the digits the file prints allow) and the rows
the header's Record Length counts (``record_length``)."""
from __future__ import annotations

import re

import numpy as np

from ..errors import InstrumentError
from .checks import is_number, printed_quanta, printed_quantum

_GATE = re.compile(r"^\s*([\d.]+)\s*%\s*to\s*([\d.]+)\s*%\s*$")


def record_length(path, length: str, gating: str, rows: int) -> None:
    """InstrumentError in one line unless the data rows are as many as the header's Record
    Length, times the gated fraction where the header gates part of the record ("25.0% to
    75.0%": half of it, to a row and the rounding of the printed percentages): a file cut
    short, at a line boundary or not, or a header that lies, is refused rather than read as
    a shorter record."""
    if not length:
        return
    n = _whole_number(length)
    if n is None or n < 2:
        raise InstrumentError(f"{path}: Record Length = {length!r}: must be a whole number of points >= 2")
    gate = _GATE.match(gating or "")
    ends = (gate.group(1), gate.group(2)) if gate else ("0", "100")
    lo, hi = float(ends[0]), float(ends[1])
    expected = n * (hi - lo) / 100
    gated = (lo, hi) != (0.0, 100.0)
    # a gated part: the percentages round the gate's ends by half a unit in their last digit each
    slack = 1 + n * (printed_quantum(ends[0]) + printed_quantum(ends[1])) / 200 if gated else 0
    if abs(rows - expected) > slack:
        said = f" gated {gating.strip()}, about {expected:.0f}" if gated else ""
        raise InstrumentError(f"{path}: Record Length says {n} points{said} but the file holds {rows} data rows "
                              f"(a file cut short, or a header that is not this record's)")


def _whole_number(text: str) -> int | None:
    try:
        value = float(text)
    except ValueError:
        return None
    return int(value) if value.is_integer() else None


TIME_TOLERANCE = 0.1  # samples: the scope's own disagreement allowed beyond what its printing rounds


def time_base(path, t, interval, zero, printed) -> tuple:
    """(first sample's time s, sample interval s) of a record whose TIME column is ``t``:
    the header's Sample Interval (the column's mean step where it gives none) from the
    column's first time, or from -Zero Index x Sample Interval where the header has a
    Zero Index (4/5/6 Series: the column prints nine digits, the fractional Zero Index
    more).

    The check, every layout alike: sample i of that time base and the TIME column may
    differ by at most what the file's printing rounds, plus TIME_TOLERANCE of a sample,

        |x0 + dt i - t_i| <= 0.1 dt + q(t_i)/2 + [q(t_0)/2 or q(z) dt/2]

    with q(x) the unit in the last digit the file prints x to (checks.printed_quanta, from
    the digits of the whole column: ``6.109e-05`` -> 1e-8 s, ``-8.000e-01`` -> 1e-4 s; a
    zero is exact) and the last term the rounding of the time base's start (the column's
    first time, or the printed Zero Index z, checks.printed_quantum); without a Sample
    Interval the step is the column's span over its samples, and the rounding of its two
    ends, (q(t_0) + q(t_last)) i / (2 (n - 1)), joins the bound. The
    Sample Interval is the scope's time-base setting, which every layout prints in full
    (shortest form, ``0.0008``, ``4e-08``; a TDS's ``1.00E-09``): taken as exact, so a
    header interval off by one unit in its last digit is refused over a long record. A
    TBS1000C prints its times to four digits, which round a time by up to 0.16 of a
    sample at 4 us/div, a 4/5/6 Series nine. Beyond that bound the header and the column
    describe two time bases: InstrumentError in one line.
    ``printed``: the TIME column's cells as the file prints them."""
    q_t = printed_quanta(printed)
    back = np.flatnonzero(np.diff(t) < -(q_t[:-1] + q_t[1:]) / 2)  # equal stamps: a rounding coarser than a sample
    if back.size or not t[-1] > t[0]:
        k = int(back[0]) if back.size else t.size - 2
        raise InstrumentError(f"{path}: the TIME column does not increase (data row {k + 2}: {printed[k + 1].strip()} "
                              f"after {printed[k].strip()}, beyond the rounding of its printed digits)")
    if interval in (None, ""):
        dt = float((t[-1] - t[0]) / (t.size - 1))  # the span: its ends' rounding spread over the record
    elif is_number(interval):
        dt = float(interval)
    else:
        raise InstrumentError(f"{path}: Sample Interval = {interval!r} is not a number")
    if not (np.isfinite(dt) and dt > 0):
        raise InstrumentError(f"{path}: Sample Interval = {interval!r}: must be a finite number > 0 s")
    # the Zero Index sets the time base where it is printed to a sample or finer (4/5/6 Series:
    # 24999.16015625); one printed coarser (2.5e+04) leaves it to the TIME column's first time
    with_zero = zero not in (None, "") and is_number(zero) and interval not in (None, "") and \
        printed_quantum(zero) <= 1
    if with_zero and not np.isfinite(float(zero)):
        raise InstrumentError(f"{path}: Zero Index = {zero!r}: must be a finite number of samples")
    x0 = -float(zero) * dt if with_zero else float(t[0])
    index = np.arange(t.size)
    grid = x0 + dt * index
    start = printed_quantum(zero) * dt / 2 if with_zero else q_t[0] / 2
    bound = TIME_TOLERANCE * dt + q_t / 2 + start
    if interval in (None, ""):  # the step from the column's ends: their rounding tilts the grid
        bound = bound + index / (t.size - 1) * (q_t[0] + q_t[-1]) / 2
    if np.any(np.abs(grid - t) > bound):
        said = (f"Zero Index = {zero} and Sample Interval = {interval}" if with_zero else
                f"Sample Interval = {interval}" if interval not in (None, "") else
                f"the TIME column's mean step ({dt:.9g} s, no Sample Interval in the header)")
        raise InstrumentError(f"{path}: {said} put the first sample at {grid[0]:.9g} s and the last at "
                              f"{grid[-1]:.9g} s, the TIME column at {t[0]:.9g} s and {t[-1]:.9g} s: they must "
                              f"agree within {TIME_TOLERANCE:g} of a sample beyond the rounding of the digits "
                              f"printed")
    return x0, dt
