"""Fitting a scene to scope records, sample by sample, through the instrument model.

The model of a channel is what the scene's instruments make of a candidate's noise-free
solution: the gauge (sensitivity, RC high-pass) and the scope's front end (probe, coupling,
bandwidth), before noise and the 8-bit conversion (instruments.devices.oscilloscope.analog). A
record's channel is compared with it after its pre-trigger baseline is removed:

    r_c(t_k) = (g_c m_c(t_k + t_0 + d_c) - y_c(t_k)) / sd_c

with nuisance parameters per record, like the ones the instruments drew: the trigger's time
on the model's clock t_0 (free), each channel's gain g_c (prior 1 +- the scene's
calibration_error) and each gauge's delay d_c (prior 0 +- misalignment_sd / the pulse speed),
the priors entering as residuals (g_c - 1)/sd_g and d_c/sd_d. sd_c: the spread of the
record's pre-trigger samples and the ADC's rounding (its step / sqrt(12); from a file of
volts, the step of the grid the values lie on), in quadrature.
"""
from __future__ import annotations

import hashlib
import math
from dataclasses import dataclass, replace

import numpy as np

from instruments.devices.gauges import GaugeDraw, PiezoGauge
from rig.errors import RigError
from rig.experiment.shot import Rig
from rig.fit.checks import at_values, check_bounds, check_distinct_channels
from rig.fit.evaluate import Pilot, calibrate, numerics, solve_rigs
from rig.fit.parameters import law_overrides
from rig.fit.points import start_values

MAX_SAMPLES = 2500  # per channel: longer records are decimated (every k-th sample)
TRIGGER_SLACK = 50e-6  # s: how far a record's trigger may sit from the model's own crossing
US = 1e-6  # nuisance times are carried in microseconds


@dataclass(frozen=True)
class Channel:
    """One record's channel as fitted: times from the trigger (s), volts less the baseline,
    the noise sd (V), and the gain's and delay's prior sds (delay_sd 0: no delay)."""

    record: int
    name: str
    t: np.ndarray
    y: np.ndarray
    sd: float
    gain_sd: float
    delay_sd: float


def noise_sd(t: np.ndarray, v: np.ndarray) -> float:
    """A record's noise (V): the spread of its quiet pre-trigger samples (the first three
    quarters before the trigger: the trigger channel's pulse rises in the last), else
    1.4826 MAD of its first differences / sqrt(2), which a smooth pulse barely moves."""
    pre = v[t < 0]
    quiet = pre[: 3 * pre.size // 4]
    if quiet.size >= 50:
        return float(np.std(quiet))
    d = np.diff(v)
    return float(1.4826 * np.median(np.abs(d - np.median(d))) / math.sqrt(2.0))


def volts_step(v: np.ndarray) -> float:
    """The step (V) of the grid a record's volts lie on, for a file that gives volts and not
    the scope's codes (a CSV export): the smallest gap between the distinct values, which
    is the ADC's step for an 8-bit record and negligible for finer data."""
    u = np.unique(v[np.isfinite(v)])
    gaps = np.diff(u)
    gaps = gaps[gaps > 1e-9 * max(float(np.max(np.abs(u))), 1e-300)] if u.size > 1 else gaps
    return float(gaps.min()) if gaps.size else 0.0


def read_channels(rig: Rig) -> dict:
    """{channel: (its instrument's settings, whether a gauge reads it)} of the scene."""
    settings = {g.channel: (g.settings, True) for g in rig.gauges}
    if rig.wall_sensor is not None:
        settings[rig.wall_sensor.channel] = (rig.wall_sensor.settings, False)
    return settings


def record_channels(rig: Rig, i: int, rec) -> list:
    """Record ``rec``'s (the i-th) channels that the scene's instruments read, as fitted
    (none for a record without them: an untriggered shot holds no channel)."""
    settings = read_channels(rig)
    speed = rig.truth().wave_speed_m_per_s or math.nan
    out = []
    for name, w in rec.waveforms.items():
        if name not in settings:
            continue
        s, gauge = settings[name]
        t, v = w.time(), w.volts().astype(float)
        step = max(1, -(-t.size // MAX_SAMPLES))
        pre = v[t < 0]
        base = float(np.median(pre)) if pre.size >= 10 else 0.0
        lsb = abs(w.preamble.y_multiplier) if w.codes is not None else volts_step(v)
        sd = max(math.hypot(noise_sd(t, v), lsb / math.sqrt(12)), 1e-9)  # 8-bit rounding beside the noise
        delay_sd = s.misalignment_sd / speed if gauge and math.isfinite(speed) else 0.0
        out.append(Channel(i, name, t[::step], v[::step] - base, sd, s.calibration_error, delay_sd))
    return out


def model_traces(rig: Rig) -> dict:
    """{channel: volts} of the rig's installed solution through its noise-free instruments,
    every solution sample interval from the impact."""
    truth = rig.truth()
    h = truth.sample_interval
    inputs = {}
    silent = np.random.default_rng(0)  # the gauges have no noise: nothing is drawn from it
    for g in rig.gauges:
        gauge = PiezoGauge(replace(g.settings, noise=0.0))
        inputs[g.channel] = gauge.read(truth.gauges[g.name].average_force, h, GaugeDraw(1.0, 0.0), silent)
    if rig.wall_sensor is not None and truth.wall_force is not None:  # a wall sensor's truth has it
        gauge = PiezoGauge(replace(rig.wall_sensor.settings, noise=0.0))
        inputs[rig.wall_sensor.channel] = gauge.read(truth.wall_force, h, GaugeDraw(1.0, 0.0), silent)
    analog = rig.scope.analog(inputs, h)
    return {"h": np.array([h]), **{ch: analog[c] for c, ch in enumerate(rig.scope.channels) if ch in inputs}}


class TraceObjective:
    """Residuals of scope records against the model's records (module doc)."""

    central_differences = True
    """The pulses move with the parameters by a good part of their rise time over a step:
    on ptfe52_gravity a forward difference's secant made the intervals of n and E 15%
    narrow and stopped the fit 0.3-0.5 sd short of the optimum (rig.fit.fitting.FD_STEP)."""

    def __init__(self, scene: str, params: tuple, records: list, overrides=(), setups=None):
        """``setups``: per record, the overrides it was fired with beyond ``overrides`` (an
        archive's virtual shots: each shot's own, a sweep's striker velocity say), its keys
        the fit fits left out; None: every record of the one set-up ``overrides`` give.
        Records of one set-up share its model; each set-up is solved per candidate."""
        self.scene, self.params = scene, tuple(params)
        self.overrides = list(overrides) + law_overrides(params, overrides)
        fitted = {q.key for q in self.params}
        per_record = [tuple(o for o in (setups[i] if setups else ()) if o.split("=", 1)[0].strip() not in fitted)
                      for i in range(len(records))]
        self.setups = sorted(set(per_record), key=per_record.index)  # in the order the records first give them
        self.setup_of = [self.setups.index(o) for o in per_record]  # record index -> set-up index
        self._start = start_values(scene, self.overrides, params)
        check_bounds(scene, self.overrides, self.params, self._start)
        rigs = [self.rig_of(self._start, g) for g in range(len(self.setups))]
        start = at_values(self.params, self._start)
        try:
            self.pilot: Pilot = calibrate(rigs)  # the fit's numerics, calibrated on its start (rig.fit.evaluate)
        except RigError as exc:
            raise RigError(f"at the fit's start values ({start}): {exc}") from None
        for g, good in enumerate(solve_rigs(rigs, self.pilot)):
            if not good:
                said = f" with {', '.join(self.setups[g])}" if self.setups[g] else ""
                raise RigError(f"the scene's own shot{said} blew up at the fit's start values ({start}); check the "
                               "scene before fitting it")
        self.channels = [c for i, rec in enumerate(records) for c in record_channels(rigs[self.setup_of[i]], i, rec)]
        if not self.channels:
            raise RigError(f"the records have none of the scene's channels ({', '.join(read_channels(rigs[0]))})")
        check_distinct_channels(self.channels)
        self.records = sorted({c.record for c in self.channels})
        self.gauges = [k for k, c in enumerate(self.channels) if c.delay_sd > 0]
        self.trigger = rigs[0].scope.trigger

    def rig_of(self, theta, setup: int = 0) -> Rig:
        """The rig of candidate ``theta`` in set-up ``setup`` (an index into self.setups)."""
        return Rig.from_scene(self.scene, self.overrides + list(self.setups[setup])
                              + [q.override(x) for q, x in zip(self.params, theta)])

    def _key(self, name: str, setup: int) -> str:
        """A model's key for a channel (or "h") of set-up ``setup``: the name alone where
        the records share one set-up (as every fit of one shot's records)."""
        return name if len(self.setups) == 1 else f"{name}@{setup}"

    def trigger_time(self, model, setup: int = 0) -> float:
        """Where the model's trigger channel first crosses the scene's trigger level (s from
        the impact, interpolated between samples; 0 if it never does): a record's time 0."""
        v = model.get(self._key(self.trigger.source, setup))
        h = float(model[self._key("h", setup)][0])
        if v is None or not math.isfinite(h):
            return 0.0
        sign = 1.0 if self.trigger.slope == "rising" else -1.0
        x = sign * (v - self.trigger.level)
        hit = np.flatnonzero((x[1:] >= 0) & (x[:-1] < 0))
        if not hit.size:
            return 0.0
        k = hit[0]
        return float((k + x[k] / (x[k] - x[k + 1])) * h)

    def spec(self) -> dict:
        out = {"kind": "traces", "scene": self.scene, "overrides": self.overrides,
               "params": [(q.key, q.lo, q.hi) for q in self.params],
               "data": [[c.record, c.name, c.sd, hashlib.sha256(c.t.tobytes() + c.y.tobytes()).hexdigest()]
                        for c in self.channels], "pilot": self.pilot.spec()}
        if len(self.setups) > 1:
            out["setups"] = [list(o) for o in self.setups]
            out["setup_of"] = self.setup_of
        return out

    def numerics(self, theta) -> dict:
        """The fit's numerics at ``theta`` (its result), rig.fit.evaluate.numerics."""
        return numerics(self.pilot, [self.rig_of(theta, g) for g in range(len(self.setups))])

    def start(self) -> np.ndarray:
        return self._start

    @property
    def n_data(self) -> int:
        """The measured values the fit compares: the records' samples."""
        return sum(c.t.size for c in self.channels)

    data_name = "the records"

    def evaluate(self, thetas: list) -> list:
        G = len(self.setups)
        rigs = [self.rig_of(t, g) for t in thetas for g in range(G)]
        ok = solve_rigs(rigs, self.pilot)
        out = []
        for k in range(len(thetas)):
            model = {}
            for g in range(G):
                rig, good = rigs[k * G + g], ok[k * G + g]
                traces = model_traces(rig) if good else {"h": np.array([math.nan])}
                model.update({self._key(name, g): v for name, v in traces.items()})
            out.append(model)
        return out

    @staticmethod
    def pack(model) -> dict:
        return model

    @staticmethod
    def unpack(z: dict):
        return z

    # nuisance: per record the trigger's offset from the model's own crossing (us), a gain
    # per channel, a delay per gauge channel (us)
    def nuisance_start(self):
        R, C = len(self.records), len(self.channels)
        d = np.array([5 * self.channels[k].delay_sd / US for k in self.gauges])
        x0 = np.concatenate((np.zeros(R), np.ones(C), np.zeros(d.size)))
        lo = np.concatenate((np.full(R, -TRIGGER_SLACK / US), np.full(C, 0.3), -d))
        hi = np.concatenate((np.full(R, TRIGGER_SLACK / US), np.full(C, 3.0), d))
        return x0, lo, hi

    def _split(self, eta):
        R, C = len(self.records), len(self.channels)
        delays = np.zeros(C)
        delays[self.gauges] = eta[R + C:]
        return eta[:R], eta[R:R + C], delays

    def traces(self, model, eta) -> list:
        """The model's value at each channel's samples (V), or None where it has none."""
        t0, gains, delays = self._split(eta)
        G = len(self.setups)
        hs = [float(model[self._key("h", g)][0]) for g in range(G)]
        starts = [self.trigger_time(model, g) / US for g in range(G)]
        out: list[np.ndarray | None] = []
        for k, c in enumerate(self.channels):
            g = self.setup_of[c.record]
            m, h = model.get(self._key(c.name, g)), hs[g]
            if m is None or not math.isfinite(h):
                out.append(None)
                continue
            tm = c.t + (t0[self.records.index(c.record)] + starts[g] + delays[k]) * US
            out.append(gains[k] * np.interp(tm, np.arange(m.size) * h, m, left=0.0, right=np.nan))
        return out

    def residuals(self, model, eta) -> np.ndarray:
        _, gains, delays = self._split(eta)
        parts = []
        for c, m in zip(self.channels, self.traces(model, eta)):
            r = np.full(c.t.size, 1e3) if m is None else (m - c.y) / c.sd
            parts.append(np.where(np.isfinite(r), r, 0.0))  # past the model's end: not compared
        priors = [(gains[k] - 1.0) / c.gain_sd for k, c in enumerate(self.channels) if c.gain_sd > 0]
        priors += [delays[k] * US / self.channels[k].delay_sd for k in self.gauges]
        return np.concatenate(parts + [np.array(priors)])

    def nuisance_jacobian(self, model, eta):
        r0 = self.residuals(model, eta)
        J = np.empty((r0.size, eta.size))
        for j in range(eta.size):
            d = 1e-3 if j < len(self.records) or j >= len(self.records) + len(self.channels) else 1e-5
            e = eta.copy()
            e[j] += d
            J[:, j] = (self.residuals(model, e) - r0) / d
        return J

    def nuisance_report(self, eta) -> dict:
        t0, gains, delays = self._split(eta)
        return {"trigger_offset_s": (t0 * US).tolist(),
                "gains": {c.name if len(self.records) == 1 else f"{c.name}@{c.record}": float(g)
                          for c, g in zip(self.channels, gains)},
                "delays_s": {self.channels[k].name: float(delays[k] * US) for k in self.gauges}}

    def relative_rms(self, model, eta) -> float:
        """rms(model - data) / the largest |data| over the channels."""
        diffs, peak = [], 0.0
        for c, m in zip(self.channels, self.traces(model, eta)):
            if m is not None:
                ok = np.isfinite(m)
                diffs.append(m[ok] - c.y[ok])
                peak = max(peak, float(np.max(np.abs(c.y))))
        return float(np.sqrt(np.mean(np.concatenate(diffs) ** 2)) / peak) if diffs and peak > 0 else math.nan
