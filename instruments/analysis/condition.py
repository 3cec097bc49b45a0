"""Condition: a scope record to calibrated dynamic forces (N) and their noise. The
baseline is the mean of the pre-trigger samples; the one-pole RC high-pass is undone,
x = y + (1/tau) * integral of y dt (trapezoid rule); volts become force through each
gauge's sensitivity (V/N). The noise comes from the pre-trigger samples too (noise_level).
The loops are compiled in _kernels/baseline.py (conditioned, noise_level)."""
from __future__ import annotations

import math

import numpy as np

from .._kernels.filters import undo_highpass
from ..errors import InstrumentError
from ..records import ScopeRecord, Waveform, time_base_mismatch
from ._kernels import baseline
from .setup import Setup

MIN_BASELINE = baseline.MIN_BASELINE  # pre-trigger samples needed to measure the noise


def record_forces(record: ScopeRecord, setup: Setup):
    """Calibrated dynamic forces (N) from a scope record: t (s from the trigger) and
    {"upper", "lower"[, "wall"]}: baseline from the pre-trigger samples, RC inverted."""
    first: Waveform | None = None
    out, t = {}, None
    for role in ("upper", "lower", "wall"):
        g = getattr(setup, role)
        if g is None:
            continue
        if g.channel not in record.waveforms:
            raise InstrumentError(f"{role} gauge channel {g.channel!r} is not in the record "
                                  f"(channels: {', '.join(record.waveforms) or 'none'})")
        w = record.waveforms[g.channel]
        h = w.preamble.x_increment
        mismatch = None if first is None else time_base_mismatch(first, w)
        if mismatch:
            raise InstrumentError(mismatch)
        if t is None:
            t, first = w.time(), w
        out[role] = baseline.conditioned(np.ascontiguousarray(w.volts(), dtype=float), int(w.preamble.trigger_index),
                                         float(h), float(g.tau_s or 0.0), float(g.sensitivity_V_per_N))
    return t, out


def record_noise(record: ScopeRecord, setup: Setup, forces: dict) -> dict:
    """role -> the noise (N) of each conditioned channel of ``forces`` (record_forces), from
    its pre-trigger samples with the floor of one code step (analysis.noise_level); None
    where the record has too short a baseline to measure it."""
    out = {}
    for role, f in forces.items():
        g = getattr(setup, role)
        w = record.waveforms[g.channel]
        out[role] = noise_level(f, w.preamble.trigger_index, _code_step(w) / g.sensitivity_V_per_N)
    return out


def _code_step(w) -> float:
    """One code step of a waveform (V): the scale factor, or for volts without codes (CSV)
    the least difference between two of its distinct values."""
    if w.codes is not None:
        return abs(w.preamble.y_multiplier)
    steps = np.diff(np.unique(w.samples))
    return float(steps.min()) if steps.size else 0.0


def noise_level(y: np.ndarray, n_pre: int, step: float = 0.0) -> float | None:
    """The noise of a conditioned signal (its unit) from its first n_pre samples, the
    pre-trigger baseline: 1.4826 x their median absolute deviation (the standard deviation
    of Gaussian noise, but robust: a spike or the start of a slow signal in the baseline
    does not inflate it as it does the standard deviation), never below the quantisation
    floor step / sqrt(12) (a flat 8-bit baseline has a MAD of 0, yet a code step hides
    that much). None with fewer than MIN_BASELINE samples: the noise cannot be measured."""
    sigma = baseline.noise_level(np.ascontiguousarray(y, dtype=float), int(n_pre), float(step))
    return None if math.isnan(sigma) else float(sigma)


def invert_rc(y: np.ndarray, h: float, tau: float) -> np.ndarray:
    """Undo a one-pole RC high-pass of time constant tau (s): x = y + (1/tau) int y dt."""
    return undo_highpass(np.ascontiguousarray(y, dtype=float), float(h), float(tau))
