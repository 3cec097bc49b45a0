"""Tektronix CSV, DPO/MSO layout: a header block of "name,value" rows, then TIME,CH1,...

All channels of one acquisition share the time base, so they go into one file. Volts are
written with 10 significant digits (an 8-bit code is reproduced exactly).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np


def write_csv(waveforms: dict, directory, stem: str) -> list:
    """Write ``<stem>.csv`` with every channel; returns [path]."""
    chans = list(waveforms)
    ws = [waveforms[c] for c in chans]
    p0 = ws[0].preamble
    rows = [
        ("Model", p0.extra.get("model", "")),
        ("Waveform Type", "ANALOG"),
        ("Point Format", "Y"),
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
    path = Path(directory) / f"{stem}.csv"
    with open(path, "w", newline="") as fh:
        for name, value in rows:
            fh.write(f"{name},{value}\n")
        fh.write("\nTIME," + ",".join(chans) + "\n")
        np.savetxt(fh, data, delimiter=",", fmt="%.10g")
    return [path]
