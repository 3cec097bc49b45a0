"""Tektronix CSV, every layout Tektronix scopes write:

- 4/5/6 Series, DPO/MSO, TBS1000C: "name,value" header rows (per-channel cells side by
  side where a file holds several channels), then a "TIME,CH1,..." row and the data columns;
- TDS1000/2000, TBS1000B: blocks of six columns, one block per channel (one to four side
  by side, separated by an empty column, or one file per channel): the header cells (Record
  Length, Sample Interval, Trigger Point, Source, Vertical Units, Horizontal Units, ...) in
  the block's first two (three, with a units column) beside time and volts in its fourth
  and fifth.

A spectrum (MATH FFT: Horizontal Units Hz), a digital record (Waveform Type DIGITAL, a
Digital Type row, D0 or CH1_D0 columns), an IQ record (Waveform Type IQ, IQ_centerFrequency
rows) are refused by name from the header (checks.analog_only), never read as a time
record of volts.
The export is the 4/5/6 Series layout, one file per channel, with the fractional Zero Index
(the trigger's place in samples) those scopes write, so that Tektronix's own reader
(tm_data_types) puts every sample where this reader does.
"""
from __future__ import annotations

import re
from dataclasses import replace
from pathlib import Path

import numpy as np

from ..errors import InstrumentError
from ..files import atomic_writes
from ..rails import flagged
from ..records import Preamble, Waveform
from .checks import analog_only, bandwidth, channel_name, is_number, screen, time_axis, vertical_unit
from .csv_columns import record_length, time_base

TDS_BLOCK = 6  # columns per channel in the TDS1000/2000 layout


def write_csv(waveforms: dict, directory, stem: str) -> list:
    """Write ``<stem>_<CH>.csv`` per channel in the 4/5/6 Series layout, all or none of them
    (instruments.files); returns the paths.

    The layout names no scope model (the virtual scope's model writes another layout).
    Times are written to 17 significant digits (they read back bit for bit), volts to 10 (an
    8-bit code is reproduced exactly); Zero Index = -x_zero / x_increment, fractional where
    the first sample is not on a multiple of the sample interval from the trigger."""
    return atomic_writes({Path(directory) / f"{stem}_{ch}.csv": _channel_writer(w, ch) for ch, w in waveforms.items()})


def _channel_writer(w: Waveform, ch: str):
    """write(path) of one channel's file."""
    p = w.preamble
    rows = [
        ("Waveform Type", "ANALOG"),
        ("Point Format", p.point_format),
        ("Horizontal Units", p.x_unit),
        ("Horizontal Scale", f"{p.x_increment * p.points / 10:.10g}"),
        ("Sample Interval", f"{p.x_increment:.17g}"),
        ("Record Length", str(p.points)),
        ("Zero Index", f"{-p.x_zero / p.x_increment:.10f}"),
        ("Gating", "0.0% to 100.0%"),
        ("Probe Attenuation", f"{p.extra.get('probe', 1):.6g}"),
        ("Vertical Units", p.y_unit),
        ("Vertical Offset", f"{p.y_zero:.10g}"),
        ("Vertical Scale", f"{p.extra.get('volts_per_div', '')}"),
        ("Vertical Position", f"{p.extra.get('position_div', 0):.6g}"),
        ("", ""),
        ("", ""),
        ("Label", p.waveform_id.replace(",", ";")),
    ]

    def write(path):
        with open(path, "w", newline="") as fh:
            for name, value in rows:
                fh.write(f"{name},{value}\n" if name else "\n")
            fh.write(f"TIME,{ch}\n")
            for t, v in zip(w.time(), w.volts()):
                fh.write(f"{t:.17g},{v:.10g}\n")

    return write


def read_csv(path) -> list:
    """Every channel of a Tektronix CSV file, in either layout (module docstring)."""
    path = Path(path)
    try:
        lines = path.read_text(encoding="utf-8-sig", errors="strict").splitlines()  # a BOM, if any, dropped
    except UnicodeDecodeError:
        raise InstrumentError(f"{path}: not a text file (not a Tektronix CSV?)") from None
    rows = [line.split(",") for line in lines]
    start = next((i for i, r in enumerate(rows) if r and r[0].strip().upper() == "TIME"), None)
    if start is not None:
        return _read_dpo(path, rows, start)
    if rows and len(rows[0]) >= 5:
        return _read_tds(path, rows)
    raise InstrumentError(f"{path}: neither Tektronix CSV layout (no TIME column header, "
                          f"and not the six-column TDS layout)")


def _floats(path, cells, row_no):
    try:
        return [float(c) for c in cells]
    except ValueError:
        bad = next(c for c in cells if not is_number(c))
        raise InstrumentError(f"{path}: row {row_no + 1}: non-numeric value {bad.strip()!r}") from None


def _read_dpo(path, rows, start) -> list:
    header = {r[0].strip(): [c.strip() for c in r[1:]] for r in rows[:start] if r and r[0].strip()}
    names = [c.strip() for c in rows[start][1:] if c.strip()]
    analog_only(path, waveform_type=_first(header, "Waveform Type"), digital_type=_first(header, "Digital Type"),
                source=next((n for n in names if _DIGITAL_COLUMN.match(n)), ""),
                iq_keys=any(k.upper().startswith("IQ_") for k in header))
    time_axis(path, "Horizontal Units", (header.get("Horizontal Units") or ["s"])[0])
    if not names:
        raise InstrumentError(f"{path}: the TIME row names no channel")
    kept = [(start + 1 + i, r) for i, r in enumerate(rows[start + 1:]) if any(c.strip() for c in r)]
    data = [_floats(path, r[:1 + len(names)], i) for i, r in kept]
    printed = [r[0] for _, r in kept]
    if len(data) < 2:
        raise InstrumentError(f"{path}: fewer than two data rows")
    short = next((i for (i, _), r in zip(kept, data) if len(r) != 1 + len(names)), None)
    if short is not None:
        raise InstrumentError(f"{path}: row {short + 1} has fewer columns than the TIME row names "
                              f"({1 + len(names)}): a file cut short?")
    record_length(path, _first(header, "Record Length"), _first(header, "Gating"), len(data))
    table = np.array(data)
    zero = header.get("Zero Index", [None])[0]
    units = header.get("Vertical Units", [])
    interval = header.get("Sample Interval", [None])[0]
    fmt = header.get("Point Format", [None])[0]
    return [_waveform(path, name.upper(), table[:, 0], printed, table[:, 1 + k], zero,
                      units[k] if k < len(units) else "V", interval, fmt,
                      screen(*(_cell(header, key, k) for key in ("Vertical Scale", "Vertical Offset",
                                                                    "Vertical Position")))
                      | bandwidth(_cell(header, "Filter Frequency", k)), zero_index=True)
            for k, name in enumerate(names)]


def _first(header: dict, key: str) -> str:
    """A header row's first value ('' where the row is missing or empty)."""
    return (header.get(key) or [""])[0]


_DIGITAL_COLUMN = re.compile(r"^(D\d+|CH\d+_D\d+)$", re.IGNORECASE)  # a 4/5/6 Series digital column


def _cell(header: dict, key: str, k: int) -> str:
    """Channel k's cell of a header row: its own, or where that is empty or missing the
    last one given before it (an MSO3012 writes "Vertical Scale,0.05," for two channels)."""
    given = [v for v in (header.get(key) or [])[:k + 1] if v]
    return given[-1] if given else ""


def _read_tds(path, rows) -> list:
    """One Waveform per six-column block; a block starts where the first row has a header
    name (Record Length) in its first cell."""
    blocks = [b for b in range(0, len(rows[0]), TDS_BLOCK) if rows[0][b].strip()]
    if not blocks or len(rows[0]) < blocks[-1] + 5:
        raise InstrumentError(f"{path}: row 1: expected blocks of six columns (TDS layout), "
                              f"found {len(rows[0])} columns")
    waves = [_read_tds_block(path, rows, b) for b in blocks]
    names = [w.channel for w in waves]  # blocks naming no source are called after the file: number them
    return [w if names.count(w.channel) == 1 else replace(w, channel=f"{w.channel}#{k + 1}")
            for k, w in enumerate(waves)]


def _read_tds_block(path, rows, b: int) -> Waveform:
    header, t, v, printed = {}, [], [], []
    for i, row in enumerate(rows):
        r = row[b:b + 5]
        if len(r) < 5:
            if any(c.strip() for c in r):
                raise InstrumentError(f"{path}: row {i + 1}, column {b + 1}: expected six columns (TDS layout)")
            continue
        if r[0].strip():
            header[r[0].strip()] = r[1].strip()
        tv = _floats(path, [r[3], r[4]], i)
        t.append(tv[0])
        v.append(tv[1])
        printed.append(r[3])
    where = f"column {b + 1}" if b else "TDS layout"
    for key in ("Record Length", "Sample Interval"):
        if key not in header:
            raise InstrumentError(f"{path}: header field {key!r} missing ({where})")
    analog_only(path, source=header.get("Source", ""))
    time_axis(path, "Horizontal Units", header.get("Horizontal Units", "s"))
    n = int(float(header["Record Length"]))
    if n != len(t):
        raise InstrumentError(f"{path}: Record Length says {n} points but the file holds {len(t)} ({where})")
    name = header.get("Source", Path(path).stem).upper()
    return _waveform(path, name, np.array(t), printed, np.array(v), header.get("Trigger Point"),
                     header.get("Vertical Units", "V"), header["Sample Interval"], header.get("Pt Fmt"),
                     screen(header.get("Vertical Scale"), _negated(header.get("Vertical Offset")), "0"))


def _negated(cell):
    """The TDS layout's Vertical Offset (V) as the screen's offset _screen takes: the TDS
    scopes write the trace's position in volts, (V + offset) / (V/div) divisions from the
    centre (a TDS2001C record at 20 mV/div, offset -43.2 mV spans 0.2 to 2.4 divisions)."""
    return f"{-float(cell)!r}" if cell not in (None, "") and is_number(cell) else cell


def _waveform(path, name, t, printed, v, trigger, unit, interval=None, point_format=None, screen=None,
              zero_index=False) -> Waveform:
    """A volts-only Waveform on the time base csv_columns.time_base checks against the TIME column
    (``trigger``: the Zero Index where ``zero_index``, else the trigger's sample;
    ``printed``: the TIME column's cells as printed, whose digits bound its rounding); an
    envelope where the header's point format says ENV or PEAK (detect); the screen
    (``screen``, _screen) kept in extra and the over-range flag set where samples sit at
    its edge (instruments.rails). The channel is called after its source (or the file),
    made a name the archive stores; the name as the file gives it is kept in extra."""
    if trigger not in (None, "") and not is_number(trigger):
        raise InstrumentError(f"{path}: trigger position = {trigger!r} is not a number")
    x0, dt = time_base(path, t, interval, trigger if zero_index else None, printed)
    idx = (int(round(float(trigger))) if trigger not in (None, "") and not zero_index
           else int(np.clip(round(-x0 / dt), 0, t.size - 1)))
    unit = vertical_unit(unit)
    pre = Preamble(points=t.size, x_increment=dt, x_zero=x0, trigger_index=idx,
                   y_multiplier=1.0, y_offset=0.0, y_zero=0.0, byte_count=0, y_unit=unit,
                   point_format="ENV" if (point_format or "Y").strip().upper().startswith(("ENV", "PEAK")) else "Y",
                   extra={"source": str(path), "name_in_file": name, **(screen or {})})
    return flagged(Waveform(channel_name(name), pre, samples=v))
