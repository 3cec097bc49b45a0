"""The instruments of many shots at once: what a study fires. Every shot's draws, gauges
and scope run on a few threads (``acquire``: compiled per-shot functions,
acquisition.shot_draws and acquisition.one_shot), the very functions PiezoGauge.read and
Oscilloscope.acquire run for one shot, so a shot of a batch has the bits it has alone
(their analysis: instruments.analysis.batch.analysed). Each shot's random numbers come from
its own generator, seeded by its seed (pcg64: np.random.default_rng(seed)'s numbers,
compiled), in the order a lone shot draws them (acquisition.shot_draws)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from numerics.threads import over_threads

from ..records import ScopeRecord
from ._kernels import acquisition
from .frontend import highpass_coefficients
from .oscilloscope import CODE_MAX, CODE_MIN, AcquisitionStatus, Oscilloscope

OK, NO_TRIGGER, PAST_INPUT = AcquisitionStatus.OK, AcquisitionStatus.NO_TRIGGER, AcquisitionStatus.PAST_INPUT
"""A record's status (Records.outcome; AcquisitionStatus.AUTO: taken untriggered in AUTO mode)."""


@dataclass(frozen=True)
class Wiring:
    """What the shots of a batch read: the gauges in the order a shot draws them (the bead
    gauges by name, then the wall sensor), each (scope channel, settings, delayed: whether
    a position error delays it), and the scope."""

    gauges: tuple
    scope: Oscilloscope

    @property
    def channels(self) -> list:
        return list(self.scope.channels)

    def wired(self) -> np.ndarray:
        """For each displayed channel, the index of the gauge on it (-1: nothing)."""
        at = {ch: k for k, (ch, _, _) in enumerate(self.gauges)}
        return np.array([at.get(ch, -1) for ch in self.scope.channels], np.int64)


@dataclass(frozen=True, eq=False)
class Records:
    """The scope records of a batch: codes (shots, channels, samples) int8, over-range
    flags (shots, channels), status (shots,) the compiled acquisition's codes (a shot's
    AcquisitionStatus: ``outcome``), times
    (shots, 2: the trigger crossing and the first sample, s), the gauges' draws (shots,
    gauges, 2: gain factor and position error m), the input they read (n_in samples
    every h s) and which channels were converted (read (channels,): the others hold code
    0)."""

    wiring: Wiring
    codes: np.ndarray
    over: np.ndarray
    status: np.ndarray
    times: np.ndarray
    draws: np.ndarray
    n_in: int
    h: float
    read: np.ndarray

    def outcome(self, s: int) -> AcquisitionStatus:
        """How shot s's acquisition ended."""
        return AcquisitionStatus(int(self.status[s]))

    def record(self, s: int) -> ScopeRecord:
        """Shot s's ScopeRecord of the channels read, as Oscilloscope.acquire returns it
        (InstrumentError where its record runs past the input)."""
        return self.wiring.scope.record_of(self.outcome(s), float(self.times[s, 0]), float(self.times[s, 1]),
                                           self.codes[s], self.over[s], self.n_in, self.h, self.read)


def acquire(forces: np.ndarray, h: float, wiring: Wiring, seeds, fixed: np.ndarray | None = None,
            wave_speed: np.ndarray | None = None, read=None) -> Records:
    """Every shot's scope record. forces (shots, gauges, samples): what each gauge reads
    (N, every h s; a bead gauge its plate's average, the wall sensor the wall's contact);
    seeds: one per shot; fixed (shots, gauges, 2): gain factors and position errors that
    replace the drawn ones (nan: keep the draw); wave_speed (shots,): the pulse's speed
    (m/s) that turns a position error into a delay (nan: none); read: the channels anyone
    will look at (None: all), the trigger's source always among them.

    A channel nobody reads is neither filtered nor converted, and its scope noise is not
    drawn where no draw of the shot comes after it; every shot still draws every other
    number in a lone shot's order (a record that starts before the impact draws the
    skipped noise before its inputs' rest noise), so the channels read have the bits they
    have in a whole record.

    The shots are shared out over numba's number of threads; each thread takes its shots
    one by one in one compiled call without Python's lock (acquisition.shots): the shot's
    draws into the thread's own noise buffers (they stay in cache), then its gauges and
    scope (acquisition.one_shot)."""
    S, G, n_in = forces.shape
    settings = [s for _, s, _ in wiring.gauges]
    scope = wiring.scope
    cal = np.array([s.calibration_error for s in settings], dtype=float)
    mis = np.array([s.misalignment_sd for s in settings], dtype=float)
    noisy = np.array([bool(s.noise) for s in settings])
    sens = np.array([s.sensitivity for s in settings], dtype=float)
    delayed = np.array([d for _, _, d in wiring.gauges])
    speed = np.full(S, np.nan) if wave_speed is None else np.asarray(wave_speed, dtype=float)
    replace = np.full((S, G, 2), np.nan) if fixed is None else np.asarray(fixed, dtype=float)
    gauge_filter = np.array([highpass_coefficients(h, s.tau) for s in settings])
    noise_sd = np.array([s.noise for s in settings], dtype=float)
    front = scope.front_panel(h)
    dx = scope.timebase.sample_interval
    L = int(scope.timebase.record_length)
    C = len(wiring.channels)
    codes = np.empty((S, C, L), np.int8)
    over = np.empty((S, C), np.bool_)
    status = np.empty(S, np.int64)
    times = np.empty((S, 2))
    drawn = np.empty((S, G, 2))
    forces = np.ascontiguousarray(forces, dtype=float)
    wired = wiring.wired()
    names = wiring.channels
    reads = np.array([read is None or ch in read or c == front.source for c, ch in enumerate(names)], np.bool_)
    drawn_rows = int(np.flatnonzero(reads)[-1]) + 1 if scope.noise_floor else 0  # scope noise drawn with the shot
    rested = np.array([g for g in wired if g >= 0 and settings[g].noise], np.int64)  # noisy before the impact
    gauges = (cal, mis, noisy, sens, delayed, gauge_filter, noise_sd)
    panel = (wired, front.probe, front.ac, front.lowpass, front.source, front.level, front.rising, front.n_pre, dx,
             front.offset, front.ymult, front.yoff, front.sd, float(CODE_MIN), float(CODE_MAX), bool(scope.noise_floor),
             front.auto)
    seeds = np.asarray(seeds, np.int64)
    over_threads(S, acquisition.shots, seeds, forces, float(h), speed, replace, gauges, panel, reads, drawn_rows,
                 rested, codes, over, status, times, drawn)
    return Records(wiring, codes, over, status, times, drawn, n_in, float(h), reads)
