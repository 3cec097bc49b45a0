"""Tektronix CSV, DPO/MSO layout: a header block of "name,value" rows, then TIME,CH1,...

All channels of one acquisition share the time base, so they go into one file. Volts are
written with 10 significant digits (an 8-bit code is reproduced exactly).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import InstrumentError
from ..files import atomic_write
from ..records import Preamble, Waveform


def write_csv(waveforms: dict, directory, stem: str) -> list:
    """Write ``<stem>.csv`` with every channel; returns [path]."""
    chans = list(waveforms)
    ws = [waveforms[c] for c in chans]
    p0 = ws[0].preamble
    rows = [
        ("Model", p0.extra.get("model", "")),
        ("Waveform Type", "ANALOG"),
        ("Point Format", p0.point_format),
        ("Horizontal Units", p0.x_unit),
        ("Horizontal Scale", f"{p0.x_increment * p0.points / 10:.6g}"),
        ("Sample Interval", f"{p0.x_increment:.10g}"),
        ("Record Length", str(p0.points)),
        ("Zero Index", str(p0.trigger_index)),
        ("Vertical Units", ",".join(w.preamble.y_unit for w in ws)),
        ("Vertical Scale", ",".join(f"{w.preamble.extra.get('volts_per_div', '')}" for w in ws)),
        ("Vertical Offset", ",".join(f"{w.preamble.y_zero:.6g}" for w in ws)),
        ("Vertical Position", ",".join(f"{w.preamble.extra.get('position_div', 0):.6g}" for w in ws)),
        ("Probe Attenuation", ",".join(f"{w.preamble.extra.get('probe', 1):.6g}" for w in ws)),
        ("Label", ",".join(w.preamble.waveform_id.replace(",", ";") for w in ws)),
    ]
    t = ws[0].time()
    data = np.column_stack([t] + [w.volts() for w in ws])
    def write(tmp):
        with open(tmp, "w", newline="") as fh:
            for name, value in rows:
                fh.write(f"{name},{value}\n")
            fh.write("\nTIME," + ",".join(chans) + "\n")
            np.savetxt(fh, data, delimiter=",", fmt="%.10g")

    return [atomic_write(Path(directory) / f"{stem}.csv", write)]


def read_csv(path) -> list:
    """Waveforms from a Tektronix CSV file, either layout:

    - DPO/MSO: "name,value" header rows, then a "TIME,CH1,..." row and the data columns;
    - TDS1000/2000: six columns per row, the header cells (Record Length, Sample Interval,
      Trigger Point, Source, Vertical Units, ...) in the first two beside time and volts
      in the fourth and fifth; one channel per file.
    """
    path = Path(path)
    try:
        lines = path.read_text(errors="strict").splitlines()
    except UnicodeDecodeError:
        raise InstrumentError(f"{path}: not a text file (not a Tektronix CSV?)") from None
    rows = [line.split(",") for line in lines]
    start = next((i for i, r in enumerate(rows) if r and r[0].strip().upper() == "TIME"), None)
    if start is not None:
        return _read_dpo(path, rows, start)
    if rows and len(rows[0]) >= 5:
        return [_read_tds(path, rows)]
    raise InstrumentError(f"{path}: neither Tektronix CSV layout (no TIME column header, "
                          f"and not the six-column TDS layout)")


def _floats(path, cells, row_no):
    try:
        return [float(c) for c in cells]
    except ValueError:
        bad = next(c for c in cells if not _is_float(c))
        raise InstrumentError(f"{path}: row {row_no + 1}: non-numeric value {bad.strip()!r}") from None


def _is_float(c):
    try:
        float(c)
        return True
    except ValueError:
        return False


def _read_dpo(path, rows, start) -> list:
    header = {r[0].strip(): [c.strip() for c in r[1:]] for r in rows[:start] if r and r[0].strip()}
    names = [c.strip() for c in rows[start][1:] if c.strip()]
    if not names:
        raise InstrumentError(f"{path}: the TIME row names no channel")
    data = [_floats(path, r[:1 + len(names)], start + 1 + i)
            for i, r in enumerate(rows[start + 1:]) if any(c.strip() for c in r)]
    if len(data) < 2:
        raise InstrumentError(f"{path}: fewer than two data rows")
    if any(len(r) != 1 + len(names) for r in data):
        raise InstrumentError(f"{path}: a data row has fewer columns than the TIME row")
    table = np.array(data)
    t = table[:, 0]
    zero = header.get("Zero Index", [None])[0]
    units = header.get("Vertical Units", [])
    interval = header.get("Sample Interval", [None])[0]
    fmt = header.get("Point Format", [None])[0]
    return [_waveform(path, name.upper(), t, table[:, 1 + k], zero, units[k] if k < len(units) else "V",
                      interval, fmt) for k, name in enumerate(names)]


def _read_tds(path, rows) -> Waveform:
    header, t, v = {}, [], []
    for i, r in enumerate(rows):
        if len(r) < 5:
            if any(c.strip() for c in r):
                raise InstrumentError(f"{path}: row {i + 1}: expected six columns (TDS layout)")
            continue
        if r[0].strip():
            header[r[0].strip()] = r[1].strip()
        tv = _floats(path, [r[3], r[4]], i)
        t.append(tv[0])
        v.append(tv[1])
    for key in ("Record Length", "Sample Interval"):
        if key not in header:
            raise InstrumentError(f"{path}: header field {key!r} missing (TDS layout)")
    n = int(float(header["Record Length"]))
    if n != len(t):
        raise InstrumentError(f"{path}: Record Length says {n} points but the file holds {len(t)}")
    name = header.get("Source", Path(path).stem).upper()
    return _waveform(path, name, np.array(t), np.array(v), header.get("Trigger Point"),
                     header.get("Vertical Units", "V"), header["Sample Interval"], header.get("Pt Fmt"))


def _waveform(path, name, t, v, trigger, unit, interval=None, point_format=None) -> Waveform:
    """A volts-only Waveform; the sample interval from the header where it is given; an
    envelope where the header's point format says ENV or PEAK (detect)."""
    try:
        dt = float(interval) if interval not in (None, "") else float(np.median(np.diff(t)))
    except ValueError:
        raise InstrumentError(f"{path}: Sample Interval = {interval!r} is not a number") from None
    if not (np.isfinite(dt) and dt > 0):
        raise InstrumentError(f"{path}: Sample Interval = {interval!r}: must be a finite number > 0 s")
    if not np.all(np.diff(t) > 0):
        raise InstrumentError(f"{path}: the time column does not increase")
    idx = int(float(trigger)) if trigger not in (None, "") else int(np.clip(round(-t[0] / dt), 0, t.size - 1))
    pre = Preamble(points=t.size, x_increment=dt, x_zero=float(t[0]), trigger_index=idx,
                   y_multiplier=1.0, y_offset=0.0, y_zero=0.0, byte_count=0, y_unit=unit or "V",
                   point_format="ENV" if (point_format or "Y").strip().upper().startswith(("ENV", "PEAK")) else "Y",
                   extra={"source": str(path)})
    return Waveform(name, pre, samples=v)
