"""Tektronix ISF: a WFMPRE text header then a binary CURVE block.

Header (full keywords, as DPO/TDS scopes write them):
  :WFMPRE:BYT_NR 1;BIT_NR 8;ENCDG BIN;BN_FMT RI;BYT_OR MSB;NR_PT n;WFID "...";PT_FMT Y;
  XUNIT "s";XINCR dt;XZERO t0;PT_OFF 0;YUNIT "V";YMULT m;YOFF o;YZERO z;:CURVE #<d><len><bytes>
PT_OFF is written 0 with XZERO the first sample's time, so readers that use
t = XZERO + XINCR (n - PT_OFF) and readers that ignore PT_OFF agree.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..records import Waveform


def _num(x: float) -> str:
    return f"{x:.10E}"


def isf_bytes(w: Waveform) -> bytes:
    """The bytes of an ISF file holding one channel's codes."""
    p = w.preamble
    nbytes = p.byte_count
    codes = np.asarray(w.codes).astype(">i1" if nbytes == 1 else ">i2")
    header = (f":WFMPRE:BYT_NR {nbytes};BIT_NR {8 * nbytes};ENCDG BIN;BN_FMT RI;BYT_OR MSB;"
              f"NR_PT {p.points};WFID \"{p.waveform_id}\";PT_FMT Y;XUNIT \"{p.x_unit}\";"
              f"XINCR {_num(p.x_increment)};XZERO {_num(p.x_zero)};PT_OFF 0;"
              f"YUNIT \"{p.y_unit}\";YMULT {_num(p.y_multiplier)};YOFF {_num(p.y_offset)};"
              f"YZERO {_num(p.y_zero)};:CURVE ")
    data = codes.tobytes()
    count = str(len(data))
    return header.encode("ascii") + f"#{len(count)}{count}".encode("ascii") + data + b"\n"


def write_isf(waveforms: dict, directory, stem: str) -> list:
    """Write one ISF file per channel, ``<stem>_<CH>.isf``; returns the paths."""
    out = []
    for ch, w in waveforms.items():
        path = Path(directory) / f"{stem}_{ch}.isf"
        path.write_bytes(isf_bytes(w))
        out.append(path)
    return out
