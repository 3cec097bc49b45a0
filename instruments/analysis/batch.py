"""The leading-pulse analysis of many shots at once: every shot's records
(instruments.devices.batch.Records) through one compiled loop (``analysed``), the very
functions the pipeline runs for one shot, so a shot of a batch has the bits it has alone."""
from __future__ import annotations

import math

import numpy as np

from ..devices.batch import OK, Records
from ..rails import Rail, clipping, code_rails, rail_of_codes
from ._kernels import batch_analysis, pulses
from .judge import report_of
from .report import Report
from .setup import Setup


def analysed(records: Records, setup: Setup) -> list:
    """Every shot's Report of its leading pulse (the pipeline's analyze_record(record,
    setup, train=False)), the numbers from one compiled loop over the shots."""
    scope = records.wiring.scope
    front = scope.front_panel(records.h)
    channels = records.wiring.channels
    roles = np.array([channels.index(setup.upper.channel), channels.index(setup.lower.channel)], np.int64)
    gauges = (setup.upper, setup.lower)
    S = records.codes.shape[0]
    answer = np.empty((S, pulses.ANSWER))
    sigma = np.empty((S, 2))
    finite = np.empty(S, np.bool_)
    dx = scope.timebase.sample_interval
    batch_analysis.analyse_shots(records.codes, records.status, records.times, dx, front.n_pre, front.ymult,
                                 front.yoff, front.offset, roles, np.array([g.tau_s or 0.0 for g in gauges]),
                                 np.array([g.sensitivity_V_per_N for g in gauges]), setup.rules.as_tuple(), answer,
                                 sigma, finite)
    limits = {ch: scope.channels[ch].bandwidth for ch in (setup.upper.channel, setup.lower.channel)}
    ticks = dx * np.arange(records.codes.shape[2])  # each record's sample times from its first
    read = records.codes[:, roles]
    lo, hi = code_rails(read)
    touches = np.any((read <= lo) | (read >= hi), axis=2)  # (shots, 2): which channels reach a rail at all
    flagged = np.any(touches | records.over[:, roles], axis=1)  # a channel at a rail or over range: a Clip to make
    out = []
    for s in range(S):
        rep = Report(beta=setup.beta, static_force_N=setup.static_force_N)
        outcome = records.outcome(s)
        if outcome is not OK:
            out.append(rep.refuse(outcome.message))
        elif not finite[s]:
            out.append(rep.refuse("samples that are not finite numbers"))
        else:
            t = records.times[s, 1] + ticks
            noise = {r: None if math.isnan(sigma[s, k]) else float(sigma[s, k])
                     for k, r in enumerate(("upper", "lower"))}
            clipped = tuple(filter(None, (clipping(channels[c], rail_of_codes(records.codes[s, c]) if touches[s, k]
                                                   else Rail(), dx, bool(records.over[s, c]))
                                          for k, c in enumerate(roles)))) if flagged[s] else ()
            out.append(report_of(answer[s], t, {}, setup, False, noise, clipped, limits))
    return out
