"""The instruments of one shot, compiled (numba): a gauge's signal chain and the
oscilloscope's acquisition. PiezoGauge.read and Oscilloscope.acquire run them for one shot;
the batched instruments (instruments/devices/batch.py) run them (``one_shot``) for every shot of a
study, on a few threads: the same code, so the same bits. Random draws come in as arrays, drawn
beforehand from each shot's generator in a fixed order (``shot_draws``, pcg64).
"""
import math

import numpy as np

from instruments._kernels import pcg64
from instruments._kernels.filters import pole_step
from numerics.jit import jit

from .quantiser import quantise
from .resample import at_positions, read_at

OK, NO_TRIGGER, PAST_INPUT, AUTO = 0, 1, 2, 3  # how an acquisition ended (AUTO: untriggered, in AUTO mode)


@jit
def gauge_signal(force, h, shift, scale, b0, b1, a1, noise_sd, z):
    """Volts of a piezo gauge (gauges.PiezoGauge), in one pass: the force (N, sampled every
    h s) read ``shift`` s earlier (linear between samples), times ``scale`` (V/N), through
    the one-pole high-pass (b0, b1, a1) from rest (filters.one_pole's operations), plus
    noise_sd x z (z: standard normal draws, or empty)."""
    n = force.shape[0]
    y = np.empty(n)
    lag = shift / h
    level = scale * read_at(force, 0 - lag)
    state = 0.0
    noisy = z.shape[0] > 0
    for k in range(n):
        yk, state = pole_step(state, scale * read_at(force, k - lag) - level, b0, b1, a1)
        y[k] = yk + noise_sd * z[k] if noisy else yk
    return y


@jit
def condition(v, probe, ac, lowpass):
    """A scope channel's analog front end on the volts at the probe tip: the input divided
    by the probe, AC coupling and the bandwidth limit (each a one-pole (b0, b1, a1) from
    rest about its input's first value, filters.one_pole; a1 nan: off; the bandwidth limit
    adds that value back), expressed back at the probe tip. One pass: the two filters'
    recursions overlap; a 1x probe divides and multiplies by 1, which changes no bit, so it
    is skipped."""
    n = v.shape[0]
    out = np.empty(n)
    unit = probe == 1.0
    coupled, limited = not math.isnan(ac[2]), not math.isnan(lowpass[2])
    z_ac = z_lp = level_ac = level_lp = 0.0
    for k in range(n):
        x = v[k] if unit else v[k] / probe
        if coupled:
            if k == 0:
                level_ac = x
            x, z_ac = pole_step(z_ac, x - level_ac, ac[0], ac[1], ac[2])
        if limited:
            if k == 0:
                level_lp = x
            y, z_lp = pole_step(z_lp, x - level_lp, lowpass[0], lowpass[1], lowpass[2])
            x = y + level_lp
        out[k] = x if unit else x * probe
    return out


TRIGGER_BAND_CODES = 5.0
"""The edge trigger's hysteresis (noise band), in codes of its source channel: 0.2 of a
division at 25 codes a division, the order of a Tektronix scope's trigger sensitivity."""


@jit
def first_crossing(x, h, level, rising, band):
    """Time (s) of the edge trigger on ``x`` (samples every h s): a comparator with
    hysteresis, as a scope's trigger is, whose state turns high where x reaches
    level + band/2 and low where x falls to level - band/2 (its state at the start: high
    where x[0] >= level). A rising trigger fires where the state turns high, a falling one
    where it turns low; the time is that of the crossing of ``level`` the turn belongs to
    (the last one before it), linearly interpolated; nan where there is none. Noise
    smaller than the band on the other flank (a falling trigger's rising flank) no longer
    fires it; on a clean edge that goes band/2 beyond the level it is the first crossing of
    the level, as without a band; a pulse that peaks less than band/2 past the level no
    longer fires it (nor does a scope's trigger)."""
    high = x[0] >= level
    last = -1  # the latest crossing of level in the trigger's direction
    for i in range(x.shape[0] - 1):
        if (x[i] < level and x[i + 1] >= level) if rising else (x[i] > level and x[i + 1] <= level):
            last = i
        turned = x[i + 1] <= level - 0.5 * band if high else x[i + 1] >= level + 0.5 * band
        if turned:
            high = not high
            if high == rising and last >= 0:
                return (last + (level - x[last]) / (x[last + 1] - x[last])) * h
    return math.nan


@jit
def scope_shot(analog, h, source, level, rising, forced, phase, n_pre, dt, offset, ymult, yoff, sd, z, lo, hi,
               codes, over, read):
    """One acquisition of conditioned channels ``analog`` (channels, samples every h s):
    the edge trigger on channel ``source``, the record of codes.shape[1] samples every dt s
    from n_pre samples before it (plus the clock's phase), read linearly between input
    samples, through the 8-bit converter (quantise) with the scope's noise sd x z[c]
    (z[c] empty: none). ``forced`` (s from the first input sample; nan: none): the trigger
    point of an untriggered acquisition in AUTO mode, taken without looking for an edge
    (status AUTO). Fills codes (channels, samples) and over of the channels ``read`` (the
    others: codes 0, not over); returns (status, time of the trigger point s, time of the
    first sample after it s)."""
    status = OK
    if math.isnan(forced):
        t_cross = first_crossing(analog[source], h, level, rising, TRIGGER_BAND_CODES * abs(ymult[source]))
        if math.isnan(t_cross):
            return NO_TRIGGER, t_cross, math.nan
    else:
        t_cross, status = forced, AUTO
    x_zero = phase - n_pre * dt
    t = t_cross + x_zero + dt * np.arange(codes.shape[1])
    if t[-1] > (analog.shape[1] - 1) * h * (1 + 1e-12):
        return PAST_INPUT, t_cross, x_zero
    pos = t / h
    for c in range(analog.shape[0]):  # read between input samples, then the converter (a pass that vectorises)
        if read[c]:
            over[c] = quantise(at_positions(analog[c], pos), offset[c], ymult[c], yoff[c], sd[c], z[c], lo, hi,
                               codes[c])
        else:
            codes[c] = 0
            over[c] = False
    return status, t_cross, x_zero


@jit
def samples_before_input(status, t_cross, x_zero, h):
    """How many input samples (every h s) to put before the input's start so that a record
    whose first sample lies before it (t_cross + x_zero < 0 s: a pre-trigger longer than
    the time from the impact to the trigger point) reads the input at rest there, with a
    margin of two; 0 where the record starts within the input or was not taken."""
    first = t_cross + x_zero
    if (status != OK and status != AUTO) or not first < 0.0:
        return 0
    return int(math.ceil(-first / h)) + 2


@jit
def at_rest_before(v, rest_sd, z_rest):
    """v (an input, every h s) with z_rest.shape[0] samples before it of the input at rest:
    its noise rest_sd x z_rest (V), or, noise-free, its first value held."""
    n_pad = z_rest.shape[0]
    out = np.empty(n_pad + v.shape[0])
    for k in range(n_pad):
        out[k] = rest_sd * z_rest[k] if rest_sd > 0.0 else v[0]
    for k in range(v.shape[0]):  # element by element: numba's array slice assignment compiles its error message
        out[n_pad + k] = v[k]
    return out


@jit(nogil=True)
def one_shot(force, h, shift, scale, gauge_filter, noise_sd, z_gauge, z_rest, wired, probe, ac, lowpass, source,
             level, rising, forced, phase, n_pre, dt, offset, ymult, yoff, sd, z_scope, lo, hi, codes, over, read):
    """One shot: gauge g reads force[g] (N, every h s) delayed by shift[g] s with gain
    scale[g] V/N, its high-pass gauge_filter[g] and noise noise_sd[g] z_gauge[g], and before
    the impact, for z_rest.shape[1] samples, its rest: noise_sd[g] z_rest[g]
    (at_rest_before); scope channel c displays gauge wired[c] (-1: nothing), with probe[c],
    ac[c] and lowpass[c] (condition), offset, ymult, yoff (the converter) and noise sd[c]
    z_scope[c]; the trigger on channel ``source`` at ``level`` V (``forced``: an AUTO
    acquisition's trigger point, s from the impact, nan: none; scope_shot), the clock's
    phase s, n_pre pre-trigger samples every dt s. Fills codes (channels, samples) and over
    (channels) of the channels ``read`` (the source among them; scope_shot); returns
    (status, the trigger crossing from the impact s, the first sample after it s)."""
    n_pad = z_rest.shape[1]
    n = force.shape[1] + n_pad
    analog = np.empty((wired.shape[0], n))
    for c in range(wired.shape[0]):
        if not read[c]:
            continue
        g = wired[c]
        if g >= 0:
            v = gauge_signal(force[g], h, shift[g], scale[g], gauge_filter[g, 0], gauge_filter[g, 1],
                             gauge_filter[g, 2], noise_sd[g], z_gauge[g])
            if n_pad:
                v = at_rest_before(v, noise_sd[g], z_rest[g])
        else:
            v = np.zeros(n)
        conditioned = condition(v, probe[c], ac[c], lowpass[c])
        for k in range(conditioned.shape[0]):  # element by element: numba's row assignment compiles its error message
            analog[c, k] = conditioned[k]
    st, t_cross, x_zero = scope_shot(analog, h, source, level, rising, forced + n_pad * h, phase, n_pre, dt, offset,
                                     ymult, yoff, sd, z_scope, lo, hi, codes, over, read)
    return st, t_cross - n_pad * h, x_zero


@jit(nogil=True)
def shot_settings(draws, fixed, sensitivity, delayed, speed, shift, scale):
    """A shot's gauges from their draws (gauges, 2: gain factor, position error m): each
    draw replaced by ``fixed`` where that is not nan (draws updated in place); shift[g] the
    delay (s) of a position error at the pulse's ``speed`` (m/s) where gauge g is
    ``delayed`` and the speed is known, else 0; scale[g] = sensitivity (V/N) x gain."""
    for g in range(draws.shape[0]):
        for k in range(2):
            if not math.isnan(fixed[g, k]):
                draws[g, k] = fixed[g, k]
        shift[g] = draws[g, 1] / speed if delayed[g] and not math.isnan(speed) else 0.0
        scale[g] = sensitivity[g] * draws[g, 0]


@jit(nogil=True)
def shot_draws(st, calibration_error, misalignment_sd, noisy, draws, z_gauge, phase_span, scope_noisy, z_scope):
    """One shot's random draws from its generator's state st (pcg64.seeded(seed): the
    numbers of np.random.default_rng(seed)), in the order a shot takes them: for each gauge
    (the bead gauges by name, then the wall sensor) its gain factor 1 + calibration_error z
    and position error misalignment_sd z (draws[:, 0], draws[:, 1]), then its noise
    (z_gauge[k], where noisy[k]); then the scope's clock phase uniform(0, phase_span)
    (returned) and each displayed channel's noise (z_scope, where scope_noisy). It runs
    without Python's lock, so the shots of a batch draw on several threads at once."""
    for k in range(draws.shape[0]):
        draws[k, 0] = 1.0 + calibration_error[k] * pcg64.standard_normal(st)
        draws[k, 1] = misalignment_sd[k] * pcg64.standard_normal(st)
        if noisy[k]:
            pcg64.normals(st, z_gauge[k])
    phase = 0.0 + phase_span * pcg64.next_double(st)  # Generator.uniform(0, span): low + span x random
    if scope_noisy:
        pcg64.normals(st, z_scope.reshape(-1))
    return phase


@jit(nogil=True)
def shots(first, last, seeds, forces, h, speed, fixed, gauges, scope, reads, drawn_rows, rested, codes, over, status,
          times, drawn):
    """Shots first..last-1 of a batch (instruments/devices/batch.acquire), one after another
    without Python's lock: each shot's draws from its seed (pcg64.seeded: numpy's
    default_rng(seed), shot_draws), its gauges' settings (shot_settings, fixed: the draws
    that replace the drawn ones), its record (one_shot) and, for a record that starts
    before the impact, the noise of the channels not read and the inputs' rest noise in
    their turn (the gauges ``rested``) and the record again. gauges: (calibration errors,
    misalignment sds, noisy, sensitivities, delayed, high-pass coefficients, noise sds);
    scope: (wired, probe, ac, lowpass, source, level, rising, n_pre, dt, offset, ymult,
    yoff, noise sd, lowest code, highest code, scope noise on, AUTO mode: a shot that does
    not trigger is taken untriggered, its trigger point at the impact). Fills codes, over,
    status, times (the trigger point, the first sample) and drawn (gain factor, position
    error)."""
    cal, mis, noisy, sens, delayed, gauge_filter, noise_sd = gauges
    wired, probe, ac, lowpass, source, level, rising, n_pre, dt, offset, ymult, yoff, sd, lo, hi, noisy_scope, \
        auto = scope
    G, n_in = forces.shape[1], forces.shape[2]
    C, L = codes.shape[1], codes.shape[2]
    z_gauge = np.zeros((G, n_in))  # a noise-free gauge's row stays 0
    z_scope = np.empty((C, L if noisy_scope else 0))
    z_none = np.empty((G, 0))
    shift, scale = np.empty(G), np.empty(G)
    for s in range(first, last):
        st = pcg64.seeded(seeds[s])
        phase = shot_draws(st, cal, mis, noisy, drawn[s], z_gauge, dt, noisy_scope, z_scope[:drawn_rows])
        shot_settings(drawn[s], fixed[s], sens, delayed, speed[s], shift, scale)
        z_rest, forced = z_none, math.nan
        for _ in range(3):
            done, t_cross, x_zero = one_shot(forces[s], h, shift, scale, gauge_filter, noise_sd, z_gauge, z_rest, wired,
                                             probe, ac, lowpass, source, level, rising, forced, phase, n_pre, dt,
                                             offset, ymult, yoff, sd, z_scope, lo, hi, codes[s], over[s], reads)
            if done == NO_TRIGGER and auto:  # AUTO: taken untriggered, its trigger point at the impact
                forced = 0.0
                continue
            n_pad = samples_before_input(done, t_cross, x_zero, h) if z_rest.shape[1] == 0 else 0
            if not n_pad:
                break
            if noisy_scope:  # the noise of the channels not read, in its turn
                pcg64.normals(st, np.empty((C - drawn_rows) * L))
            z_rest = np.zeros((G, n_pad))
            for g in rested:  # drawn after the shot's other draws, in the displayed channels' order
                pcg64.normals(st, z_rest[g])
        status[s] = done
        times[s, 0] = t_cross
        times[s, 1] = x_zero
