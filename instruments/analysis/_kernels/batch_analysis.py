"""The leading-pulse analysis of a batch of scope records, compiled (numba): each shot's
channels from their 8-bit codes to forces, their noise and leading_pair's answer, over
the shots on as many threads as numba's. instruments/analysis/batch.analysed turns the numbers
into Reports. The same functions as a lone record's analysis (baseline.py, pulses.py), so the same bits.
"""
import math

import numpy as np

from instruments._kernels.filters import undo_highpass_into
from instruments.devices.batch import OK
from numerics.jit import jit
from numerics.threads import over_threads

from .baseline import baseline_mean, noise_level
from .pulses import leading_pair


@jit
def analyse_shot(codes, time0, dx, n_pre, ymult, yoff, yzero, roles, rails, tau, sens, rules, answer, sigma,
                 touches):
    """One shot's leading_pair answer, its channels' noise and whether each reaches a rail
    of its converter (roles: the upper and lower gauges' channels; rails: the lowest and
    highest code; tau s, sens V/N: their gauges'); False where a sample is not a finite
    number."""
    t = time0 + dx * np.arange(codes.shape[1])
    f = np.empty((2, codes.shape[1]))
    for r in range(2):
        c = roles[r]
        volts = f[r]
        at_rail = False
        for k in range(codes.shape[1]):  # the codes' volts (records.ScopeRecord's operations)
            volts[k] = yzero[c] + ymult[c] * (np.float64(codes[c, k]) - yoff[c])
            at_rail |= (codes[c, k] <= rails[0]) | (codes[c, k] >= rails[1])
        touches[r] = at_rail
        undo_highpass_into(volts, baseline_mean(volts, n_pre), dx, tau[r], sens[r], volts)  # conditioned, in place
        sigma[r] = noise_level(volts, n_pre, abs(ymult[c]) / sens[r])
        for k in range(codes.shape[1]):
            if not math.isfinite(volts[k]):
                return False
    leading_pair(t, f[0], f[1], sigma[0], sigma[1], rules, answer)
    return True


@jit(nogil=True)
def analyse_range(first, last, codes, status, times, dx, n_pre, ymult, yoff, yzero, roles, rails, tau, sens, rules,
                  answer, sigma, finite, touches):
    """analyse_shot for shots first..last-1 whose record status is OK (analyse_shots'
    arguments), without the GIL: the ranges run on threads."""
    for s in range(first, last):
        answer[s, :] = math.nan
        sigma[s, :] = math.nan
        finite[s] = True
        touches[s, :] = False
        if status[s] == OK:
            finite[s] = analyse_shot(codes[s], times[s, 1], dx, n_pre, ymult, yoff, yzero, roles, rails, tau, sens,
                                     rules, answer[s], sigma[s], touches[s])


def analyse_shots(codes, status, times, dx, n_pre, ymult, yoff, yzero, roles, rails, tau, sens, rules, answer, sigma,
                  finite, touches):
    """analyse_shot for every shot whose record status is OK (codes (shots, channels,
    samples), times[:, 1]: each record's first sample s; rails (2,): the converter's lowest
    and highest code); answer and sigma nan, touches (shots, 2) False elsewhere.
    The shots are shared out in contiguous ranges over as many threads as numba's
    (numba.get_num_threads), each running analyse_range: a numba parallel loop over them
    doubled this analysis' compile time."""
    over_threads(codes.shape[0], analyse_range, codes, status, times, dx, n_pre, ymult, yoff, yzero, roles, rails, tau,
                 sens, rules, answer, sigma, finite, touches)
