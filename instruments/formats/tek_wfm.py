"""Tektronix .wfm (WFM#001/002/003, the native files of DPO/MSO and 4/5/6 Series scopes),
read through RigolWFM, which parses the three layouts from their Kaitai descriptions.

(Tektronix's own tm_data_types reads these files too, but it pins numpy < 2 and
numba < 0.61, which the rig's stack cannot take; its values agree with RigolWFM's on
Tektronix's sample file: tests/instruments/test_realdata.py.)

The file's codes and its explicit dimension's scale and offset become the same Waveform
as an ISF record: volts = y_zero + y_multiplier * code with y_multiplier the file's volts
per code and y_zero its volts at code 0; time = x_zero + x_increment * n, x_zero the first
valid sample's time relative to the trigger (s). RigolWFM hands over float32 volts; the
codes are recovered exactly from them (the scale is the file's own). One analog record per
file; the file names no source channel, so the Waveform is called after the file.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import InstrumentError
from ..records import Preamble, Waveform


def read_wfm(path) -> list:
    """The analog record of a Tektronix .wfm file, as one Waveform (codes + scaling)."""
    from RigolWFM.wfm import Wfm

    path = Path(path)
    try:
        ch = Wfm.from_file(str(path), "TEK").channels[0]
    except Exception as exc:  # the library's own errors name no file
        detail = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise InstrumentError(f"{path}: not a readable Tektronix .wfm analog record ({detail})") from None
    volts, times = np.asarray(ch.volts, dtype=np.float64), np.asarray(ch.times, dtype=np.float64)
    scale, offset = float(ch.volt_scale), float(ch.volt_offset)
    if volts.size < 2 or not (np.isfinite(scale) and scale != 0):
        raise InstrumentError(f"{path}: a .wfm record of {volts.size} samples at {scale!r} V per code "
                              f"(needs >= 2 samples and a finite non-zero scale)")
    dx = float(times[1] - times[0])
    if not (np.isfinite(dx) and dx > 0):
        raise InstrumentError(f"{path}: sample interval {dx!r}: must be a finite number > 0 s")
    codes = np.rint((volts - offset) / scale)
    width = path.open("rb").read(16)[15]  # static file info: bytes per point
    dtype = np.int8 if width == 1 else np.int16
    info = np.iinfo(dtype)
    if codes.min() < info.min or codes.max() > info.max:
        raise InstrumentError(f"{path}: codes outside {dtype.__name__} ({width} byte(s) per point): "
                              f"not an integer-coded analog record")
    x0 = float(times[0])
    pre = Preamble(points=volts.size, x_increment=dx, x_zero=x0,
                   trigger_index=int(np.clip(round(-x0 / dx), 0, volts.size - 1)),
                   y_multiplier=scale, y_offset=0.0, y_zero=offset, byte_count=np.dtype(dtype).itemsize,
                   extra={"source": str(path), "format": "Tektronix WFM"})
    return [Waveform(path.stem, pre, codes=codes.astype(dtype))]
