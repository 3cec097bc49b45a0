"""Refine: a pulse's time and amplitude from a least-squares parabola through the samples
within ``rules.top`` of its maximum (accurate on 8-bit records whose tops are plateaus of
equal codes), its widths where it crosses 50% (FWHM) and 1% (base) of its amplitude,
interpolated linearly; and the delay between two pulses by cross-correlation, with a
parabola through the correlation peak. The loops are compiled in _kernels/pulses.py
(refine) and _kernels/correlation.py (xcorr_lag)."""
from __future__ import annotations

import numpy as np

from ._kernels import correlation, pulses
from .pulse import DEFAULT_RULES, PeakRules, Pulse


def refined(t: np.ndarray, f: np.ndarray, pulse: Pulse, rules: PeakRules = DEFAULT_RULES) -> Pulse:
    """The pulse's time and amplitude from its parabola, and its FWHM and 1% base width."""
    i = int(np.rint((pulse.time - t[0]) / (t[1] - t[0])))
    return Pulse(*(float(x) for x in pulses.refine(np.ascontiguousarray(t, dtype=float),
                                                   np.ascontiguousarray(f, dtype=float), i, rules.top)))


def xcorr_delay(t, fa, pa: Pulse, fb, pb: Pulse) -> float:
    """Delay (s) of pulse b after pulse a by cross-correlation of the leading pulses.

    The window of a spans one FWHM either side of its maximum (the main lobe, clear of the
    next pulse of a train); b is searched within a window twice as wide around its own
    maximum; parabola through the correlation peak (compiled: _kernels/correlation.py)."""
    c = np.ascontiguousarray
    return float(correlation.xcorr_lag(c(t, dtype=float), c(fa, dtype=float), pa.time, pa.fwhm, c(fb, dtype=float),
                                  pb.time))
