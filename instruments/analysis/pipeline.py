"""The measurement pipeline: records (real or virtual) -> calibrated forces -> pulses,
speed and amplitude, as Daraio et al. (2006) measured them. It reads top-down, one stage
a module: condition (condition.py: volts to forces, the RC high-pass undone, the noise),
find and refine (find.py, refine.py: the leading pulses and their delay, here in one
compiled call, _kernels/pulses.leading_pair), judge (judge.py with plausibility.py and
distortion.py: each figure given or refused with its reason) and report (report.py). It
needs no simulator: what it knows of the physics arrives as data in a Setup (setup.py).

No figure without a reason: each one the analysis cannot give is None, and
``Report.reasons`` says why (an envelope or untriggered record, non-finite samples, no
pulse standing ``rules.snr`` noise levels above the pre-trigger baseline, the same record
on both gauges, the lower pulse first, a speed that fails instruments.analysis.plausibility). An
implausible speed is not given: the speed figures are None and the reason quotes the value.
"""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from ..rails import clipping, rail
from ..records import ScopeRecord
from ._kernels import pulses
from .condition import record_forces, record_noise
from .judge import report_of
from .report import Report
from .setup import Setup


def analyze_record(record: ScopeRecord, setup: Setup, train: bool = True) -> Report:
    """The full pipeline on one scope record, with the SNR rule on each gauge's noise.
    train=False: the leading pulse only (see analyze_forces; the wall channel is not read).
    An untriggered or envelope record, or one with non-finite samples, gives a report of
    reasons only."""
    rep = Report(beta=setup.beta, static_force_N=setup.static_force_N)
    if not record.triggered:
        return rep.refuse(f"the scope did not trigger ({record.reason or 'no reason recorded'})")
    if not train:
        setup = replace(setup, wall=None)
    roles = [r for r in ("upper", "lower", "wall") if getattr(setup, r) is not None]
    for role in roles:
        w = record.waveforms.get(getattr(setup, role).channel)
        if w is not None and w.preamble.point_format == "ENV":
            return rep.refuse(f"{w.channel}: an envelope (peak-detect) record holds min/max pairs, not samples; "
                              f"record in sample or average mode")
    t, forces = record_forces(record, setup)
    bad = [getattr(setup, r).channel for r in roles if not np.all(np.isfinite(forces[r]))]
    if bad:
        return rep.refuse(f"{', '.join(bad)}: samples that are not finite numbers (a non-finite scale factor "
                          f"or sample in the file?)")
    waves = [record.waveforms[getattr(setup, r).channel] for r in ("upper", "lower")]
    clipped = tuple(filter(None, (clipping(w.channel, rail(w), w.preamble.x_increment, w.overrange)
                                  for w in waves)))
    limits = {w.channel: w.preamble.extra.get("bandwidth_Hz") for w in waves}
    return analyze_forces(t, forces, setup, train, record_noise(record, setup, forces), clipped, limits)


def analyze_forces(t: np.ndarray, forces: dict, setup: Setup, train: bool = True, noise: dict | None = None,
                   clipped: tuple = (), bandwidth: dict | None = None) -> Report:
    """Speed, amplitudes, pulse count and widths from dynamic forces (baseline 0).
    train=False leaves the solitary train uncounted (pulses None): studies that need only
    the leading pulse skip the wall channel and two peak searches. noise: role -> noise (N;
    None: unmeasurable, and no pulse is accepted) for the SNR rule; None: noise-free
    signals (the truth), no SNR rule; clipped: the rails.Clip of each gauge channel that ran
    off the scope's range (report_of); bandwidth: channel -> its bandwidth limit (Hz,
    report_of). The leading pulses and their delay come from the compiled
    _kernels/pulses.leading_pair, as in a study's batched analysis."""
    sigma = {r: math.nan if noise is None or noise.get(r) is None else float(noise[r]) for r in ("upper", "lower")}
    answer = np.empty(pulses.ANSWER)
    c = np.ascontiguousarray
    pulses.leading_pair(c(t, dtype=float), c(forces["upper"], dtype=float), c(forces["lower"], dtype=float),
                        sigma["upper"], sigma["lower"], setup.rules.as_tuple(), answer)
    return report_of(answer, t, forces, setup, train, noise, clipped, bandwidth)

