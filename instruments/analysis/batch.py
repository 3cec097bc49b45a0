"""The leading-pulse analysis of many shots at once: every shot's records
(instruments.devices.batch.Records) through one compiled loop, the very functions the
pipeline runs for one shot, and the judge's rules over the whole batch (verdicts.py), so a
shot of a batch has the bits it has alone: ``analysed`` words each shot's Report,
``analysed_figures`` gives a study the figures as arrays, with no Report built."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..devices.batch import OK, Records
from ..rails import Rail, clipping, code_rails, rail_of_codes
from . import verdicts
from ._kernels import batch_analysis, pulses
from .distortion import CLIPPED_FIGURES, flat_top_doubt, speed_survives, with_clipping
from .judge import ROLES, bandwidths, report_at
from .report import Report
from .setup import Setup
from .verdicts import ARRAY_FIGURES, Verdicts


def analysed(records: Records, setup: Setup) -> list:
    """Every shot's Report of its leading pulse (the pipeline's analyze_record(record,
    setup, train=False)), the numbers from one compiled loop over the shots."""
    judged = _judged(records, setup)
    v, ticks, bandwidth = judged.verdicts, judged.ticks, judged.bandwidth
    out = []
    for s in range(records.codes.shape[0]):
        rep = Report(beta=setup.beta, static_force_N=setup.static_force_N)
        outcome = records.outcome(s)
        if outcome is not OK:
            out.append(rep.refuse(outcome.message))
        elif not judged.finite[s]:
            out.append(rep.refuse("samples that are not finite numbers"))
        else:
            noise = {r: None if math.isnan(judged.sigma[s, k]) else float(judged.sigma[s, k])
                     for k, r in enumerate(ROLES)}
            rep = report_at(v, s, judged.answers[s], records.times[s, 1] + ticks, {}, setup, False, noise, bandwidth)
            out.append(with_clipping(rep, _clips(records, judged, s)))
    return out


def analysed_figures(records: Records, setup: Setup) -> dict:
    """The figures of ``analysed``'s Reports (verdicts.ARRAY_FIGURES name -> (shots,), SI
    units, nan where a Report's is None) without a Report: the verdicts' arrays, less the
    shots the acquisition or non-finite samples refuse and what the clipping rule takes."""
    judged = _judged(records, setup)
    v = judged.verdicts
    figures = {name: x.copy() for name, x in v.figures.items()}
    refused = (records.status != int(OK)) | ~judged.finite
    for x in figures.values():
        x[refused] = np.nan
    for s in np.flatnonzero(judged.flagged & ~refused):
        clipped = _clips(records, judged, int(s))
        if not clipped:
            continue
        speed_kept = v.speed_given[s] and speed_survives(flat_top_doubt(clipped), float(v.flight[s]))
        for name in (CLIPPED_FIGURES if speed_kept else ARRAY_FIGURES):
            figures[name][s] = np.nan
    return figures


@dataclass(frozen=True, eq=False)
class Judged:
    """A batch's compiled analysis and the rules' verdicts on it: answers (shots, ANSWER),
    sigma (shots, 2: each gauge's noise, nan: not measurable), finite (shots,), verdicts,
    roles (2,: the gauge channels' rows in the records), touches (shots, 2: the channel
    reaches a rail; False where the acquisition did not end OK), flagged (shots,: a gauge
    channel at a rail or over range), ticks (samples,: a record's sample times from its
    first), bandwidth (channel -> its limit, Hz)."""

    answers: np.ndarray
    sigma: np.ndarray
    finite: np.ndarray
    verdicts: Verdicts
    roles: np.ndarray
    touches: np.ndarray
    flagged: np.ndarray
    ticks: np.ndarray
    bandwidth: dict


def _judged(records: Records, setup: Setup) -> Judged:
    scope = records.wiring.scope
    front = scope.front_panel(records.h)
    channels = records.wiring.channels
    roles = np.array([channels.index(setup.upper.channel), channels.index(setup.lower.channel)], np.int64)
    gauges = (setup.upper, setup.lower)
    S = records.codes.shape[0]
    answers = np.empty((S, pulses.ANSWER))
    sigma = np.empty((S, 2))
    finite = np.empty(S, np.bool_)
    touches = np.empty((S, 2), np.bool_)  # (shots, 2): a gauge channel reaches a rail of its converter at all
    dx = scope.timebase.sample_interval
    batch_analysis.analyse_shots(records.codes, records.status, records.times, dx, front.n_pre, front.ymult,
                                 front.yoff, front.offset, roles, np.array(code_rails(records.codes), np.int64),
                                 np.array([g.tau_s or 0.0 for g in gauges]),
                                 np.array([g.sensitivity_V_per_N for g in gauges]), setup.rules.as_tuple(), answers,
                                 sigma, finite, touches)
    bandwidth = {ch: scope.channels[ch].bandwidth for ch in (setup.upper.channel, setup.lower.channel)}
    ticks = dx * np.arange(records.codes.shape[2])  # each record's sample times from its first
    first = records.times[:, 1] + ticks[0]  # t[0], t[1] and t[-1] of each record as the pipeline has them
    span = (records.times[:, 1] + ticks[-1]) - first
    h = (records.times[:, 1] + ticks[min(1, ticks.size - 1)]) - first
    v = verdicts.judge(answers, span, h, sigma, setup, bandwidths(setup, bandwidth))
    flagged = np.any(touches | records.over[:, roles], axis=1)  # a channel at a rail or over range: a Clip to make
    return Judged(answers, sigma, finite, v, roles, touches, flagged, ticks, bandwidth)


def _clips(records: Records, judged: Judged, s: int) -> tuple:
    """The rails.Clip of shot s's gauge channels that ran off the scope's range."""
    if not judged.flagged[s]:
        return ()
    channels, dx = records.wiring.channels, records.wiring.scope.timebase.sample_interval
    return tuple(filter(None, (clipping(channels[c], rail_of_codes(records.codes[s, c]) if judged.touches[s, k]
                                        else Rail(), dx, bool(records.over[s, c]))
                               for k, c in enumerate(judged.roles))))
