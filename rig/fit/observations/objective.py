"""Fitting a scene to observations (rig.fit.observations.kinds): each candidate parameter
set fires every shot the observations need (each its scene with the candidate's values and
its own overrides, all solved in one batched call, rig.fit.evaluate), and an observation's
residual is its figure on the shots' noise-free truth against its observed value:

    r_i = (m_i(theta) - y_i) / sd_i

A figure the model cannot give (a shot the scene refuses or that blew up, no pulse) has
the residual NO_FIGURE. A count of pulses is a step function of the parameters: it enters
chi2 but moves no derivative unless a step crosses a jump.
"""
from __future__ import annotations

import functools
import math
from dataclasses import asdict

import numpy as np

from rig.errors import RigError, invalid
from rig.experiment.shot import Rig
from rig.fit.checks import at_values, check_bounds
from rig.fit.evaluate import Pilot, calibrate, numerics, solve_rigs
from rig.fit.observations.kinds import LIMITS, measure
from rig.fit.parameters import law_overrides
from rig.fit.points import start_values

NO_FIGURE = 1e3
"""The residual (in standard deviations) of an observation the model gives no figure for."""


class ObservationObjective:
    """Residuals of observations against the model's figures (module doc); ``start``: where
    the fit starts and its pilot is calibrated (SI; None: start_values)."""

    central_differences = False  # the figures move smoothly with the parameters: forward, half the solves

    def __init__(self, scene: str, params: tuple, observations: tuple, overrides=(), source: str = "",
                 start=None):
        self.scene, self.params, self.observations, self.source = scene, tuple(params), tuple(observations), source
        self.overrides = list(overrides) + law_overrides(params, overrides)
        keys = {p.key for p in self.params}
        for obs in self.observations:
            for shot in obs.shots():
                for o in shot.overrides:
                    if o.split("=", 1)[0].strip() in keys:
                        raise invalid(f"{obs.label}: set", o, "a fitted --param key: the fit sets it; leave it out")
        self.shot_list = list(dict.fromkeys(s for obs in self.observations for s in obs.shots()))
        self.value = np.array([o.value for o in self.observations])
        self.sd = np.array([o.sd for o in self.observations])
        sides = [LIMITS.get(o.limit, (-math.inf, math.inf)) for o in self.observations]
        self.residual_lo = np.array([lo for lo, _ in sides])  # one-sided observations: their residual's range
        self.residual_hi = np.array([hi for _, hi in sides])
        self._start = start_values(scene, self.overrides, params) if start is None else np.asarray(start, float)
        check_bounds(scene, self.overrides, self.params, self._start)

    def rigs_of(self, theta) -> list:
        """The rig of each shot at candidate ``theta`` (None where its scene refuses it)."""
        fitted = [q.override(x) for q, x in zip(self.params, theta)]
        out: list[Rig | None] = []
        for s in self.shot_list:
            try:
                out.append(Rig.from_scene(s.scene, self.overrides + fitted + list(s.overrides)))
            except RigError:
                out.append(None)
        return out

    @functools.cached_property
    def pilot(self) -> Pilot:
        """The fit's numerics, calibrated once on the start values' shots (rig.fit.evaluate)."""
        start = at_values(self.params, self._start)
        rigs = self.rigs_of(self._start)
        if None in rigs:
            shot = self.shot_list[rigs.index(None)]
            raise RigError(f"the scene refuses the fit's start values ({start}) for the shot {shot.label()}")
        try:
            return calibrate(rigs)
        except RigError as exc:
            raise RigError(f"at the fit's start values ({start}): {exc}") from None

    def spec(self) -> dict:
        """What the fit's evaluations depend on (the key of its cache), the pilot's numerics
        included."""
        return {"kind": "observations", "scene": self.scene, "overrides": self.overrides,
                "params": [(q.key, q.lo, q.hi) for q in self.params],
                "data": [{k: v for k, v in asdict(o).items() if k != "label"} for o in self.observations],
                "pilot": self.pilot.spec()}

    def numerics(self, theta) -> dict:
        """The fit's numerics at ``theta`` (its result), rig.fit.evaluate.numerics."""
        return numerics(self.pilot, [r for r in self.rigs_of(theta) if r is not None])

    def start(self) -> np.ndarray:
        return self._start

    @property
    def n_data(self) -> int:
        """The measured values the fit compares: one per observation."""
        return len(self.observations)

    @property
    def data_name(self) -> str:
        return f"--observations {self.source}"

    def evaluate(self, thetas: list) -> list:
        """The model's figure of every observation (SI, nan where it has none) at each
        candidate, all candidates' shots solved in one batched call."""
        per = [self.rigs_of(t) for t in thetas]
        flat = [r for rigs in per for r in rigs if r is not None]
        ok = dict(zip(map(id, flat), solve_rigs(flat, self.pilot)))
        out = []
        for rigs in per:
            truths = {s: r.truth() if r is not None and ok[id(r)] else None for s, r in zip(self.shot_list, rigs)}
            out.append(np.array([measure(o, truths) for o in self.observations]))
        return out

    @staticmethod
    def pack(model) -> dict:
        return {"figures": model}

    @staticmethod
    def unpack(z: dict):
        return z["figures"]

    def residuals(self, model, eta) -> np.ndarray:
        """(figure - value) / sd; a one-sided observation's 0 on its allowed side (LIMITS)."""
        r = (model - self.value) / self.sd
        r = np.clip(r, self.residual_lo, self.residual_hi)
        return np.where(np.isfinite(r), r, NO_FIGURE)

    def relative_residuals(self, model) -> np.ndarray:
        """model / observed - 1 of each observation (nan without a figure or where observed is 0)."""
        with np.errstate(divide="ignore", invalid="ignore"):
            rel = model / self.value - 1.0
        return np.where(np.isfinite(rel), rel, np.nan)

    def relative_rms(self, model, eta) -> float:
        """RMS of model / observed - 1 (observations without a figure, or observed 0, left out)."""
        rel = self.relative_residuals(model)
        rel = rel[np.isfinite(rel)]
        return float(np.sqrt(np.mean(rel ** 2))) if rel.size else math.nan

    def rows(self, model, residuals) -> list:
        """One row per observation for residuals.csv: what (a one-sided one's limit beside its
        kind), where, observed, sd, model, residual."""
        return [[o.label, o.kind + (f" of {o.of}" if o.of else "") + (f" ({o.limit})" if o.limit else ""), o.gauge,
                 o.shot.label() + ("" if o.over is None else f" / {o.over.label()}"), o.unit, o.value, o.sd, float(m),
                 float(r)]
                for o, m, r in zip(self.observations, model, residuals)]

    def figures(self, model, residuals) -> list:
        """[{observation, kind, gauge, shot, unit, observed, sd, model, residual}] for fit.json
        (model None where the fitted model gives no figure)."""
        return [dict(zip(("observation", "kind", "gauge", "shot", "unit", "observed", "sd", "model", "residual"),
                         row[:7] + [row[7] if math.isfinite(row[7]) else None, row[8]]))
                for row in self.rows(model, residuals)]

    ROW_HEADER = ["observation", "kind", "gauge", "shot", "unit", "observed", "sd", "model",
                  "normalised (model - observed) / sd"]

    @staticmethod
    def nuisance_start():
        return np.zeros(0), np.zeros(0), np.zeros(0)

    def nuisance_jacobian(self, model, eta):
        return np.zeros((len(self.observations), 0))

    @staticmethod
    def nuisance_report(eta) -> dict:
        return {}
