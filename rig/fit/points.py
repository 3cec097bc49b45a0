"""Fitting a scene to measured (F_d, V_s) points, with uncertainties on both coordinates.

For each configuration of the points (e.g. with and without the magnet) and each candidate
parameter set, the model is the curve V_s(F_d) of the leading pulse that virtual shots give
over a fixed set of striker velocities (rig.fit.evaluate.curves: the truth analysis, as the
published numerics were analysed). A point's residual is its speed's distance to the curve
at its force, in units of the effective standard deviation (errors in variables, the
effective-variance method: Orear, Am. J. Phys. 50, 912 (1982)):

    r_i = (V(F_i) - V_i) / sqrt(sd_V,i^2 + (dV/dF)^2 sd_F,i^2)

A point of an amplitude larger than any the curve reaches over its striker velocities (a
model whose pulses stop growing: contacts that yield) is unreachable: its residual is its
distance to the curve's end (F_e, V_e), sqrt(((V_e - V_i) / sd_eff)^2 + ((F_i - F_e) / sd_F)^2)
with the sign of V_e - V_i, which meets the residual above where F_i = F_e.
"""
from __future__ import annotations

import functools

import numpy as np

from rig.errors import RigError
from rig.experiment import scene as scene_io
from rig.fit.checks import at_values, check_bounds
from rig.fit.data import Points
from rig.fit.evaluate import Curve, Pilot, calibrate, curves, leading_window, numerics, shot_rigs
from rig.fit.parameters import law_overrides

VELOCITY_FACTORS = (0.35, 0.5, 0.7, 1.0, 1.4, 2.0, 2.8, 3.0)
"""The striker velocities of a curve, times the scene's own: for the published 0.89 m/s,
0.31-2.67 m/s, drops of 0.5-36 cm (striker_drops), the amplitudes of Table 1 of Daraio et al.
(2006) and beyond for the models fitted to it."""
NO_CURVE = 1e3
"""The residual (in standard deviations) of a point whose configuration gave no curve."""


def striker_drops(scene: str, overrides, velocities) -> dict:
    """The drop height each striker velocity needs, h = v^2 / (2 g): the striker falls freely
    (the scene models no loss on its way: the holder's drag and friction act on the beads),
    and where it is released against the holder: the tube (holder.length) leaves its length
    less the chain's stack and the striker's length above the chain's top ("free_length_m");
    a higher drop releases the striker above the tube's open top and lets it fall in
    ("above_tube_m", 0 inside the tube). A horizontal holder has no drop ("drops" empty)."""
    from rig.experiment.shot import Rig

    rig = Rig.from_scene(scene, list(overrides))
    h, g = rig.holder, rig.holder.gravity
    free = h.length - sum(b.diameter for b in rig.chain.beads) - rig.striker.length
    drops = [] if g <= 0 else [{"velocity_m_per_s": float(v), "drop_height_m": float(v * v / (2 * g)),
                                "above_tube_m": float(max(v * v / (2 * g) - free, 0.0))} for v in velocities]
    return {"holder_length_m": h.length, "free_length_m": free, "drops": drops}


def scene_value(values: dict, key: str):
    node = values
    for p in key.split("."):
        if not isinstance(node, dict) or p not in node:
            return None
        node = node[p]
    return node if isinstance(node, (int, float)) and not isinstance(node, bool) else None


def start_values(scene: str, overrides, params) -> np.ndarray:
    """Each parameter's scene value where the scene sets it inside the bounds, else the
    middle of its bounds."""
    values = scene_io.load(scene, overrides).values
    out = []
    for p in params:
        v = scene_value(values, p.key)
        out.append(v if v is not None and p.lo <= v <= p.hi else 0.5 * (p.lo + p.hi))
    return np.array(out, dtype=float)


class PointObjective:
    """Residuals of Points against the model's curves (module doc); ``start``: where the
    fit starts and its pilot is calibrated (SI; None: start_values)."""

    central_differences = False  # speed curves change slowly with the parameters: half the solves

    def __init__(self, scene: str, params: tuple, points: Points, overrides=(), start=None):
        self.scene, self.params, self.points = scene, tuple(params), points
        self.overrides = list(overrides) + law_overrides(params, overrides)
        self.configs = points.configurations()
        self.config_of = np.array([self.configs.index(c) for c in points.configs])
        v0 = scene_io.load(scene, self.overrides).values["striker"]["velocity"]
        self.velocities = v0 * np.array(VELOCITY_FACTORS)
        self._start = start_values(scene, self.overrides, params) if start is None else np.asarray(start, float)
        check_bounds(scene, self.overrides, self.params, self._start)

    def shots(self, theta, duration: float = float("inf")) -> list:
        """The rigs of candidate ``theta``'s shots, each configuration at each velocity,
        simulated for ``duration`` (s; inf: the scene's own)."""
        overrides = [self.candidate_overrides(theta, c) for c in self.configs]
        return shot_rigs(self.scene, overrides, self.velocities, duration)[0]

    @functools.cached_property
    def pilot(self) -> Pilot:
        """The fit's numerics, calibrated once on the start values' shots over their
        leading window (rig.fit.evaluate)."""
        start = at_values(self.params, self._start)
        overrides = [self.candidate_overrides(self._start, c) for c in self.configs]
        rigs, _, refused = shot_rigs(self.scene, overrides, self.velocities)
        if not rigs:
            raise RigError(f"the scene refuses the fit's start values ({start}): {refused[0]}")
        try:
            window = leading_window(rigs)
            return calibrate(self.shots(self._start, window), window)
        except RigError as exc:
            raise RigError(f"at the fit's start values ({start}): {exc}") from None

    def spec(self) -> dict:
        """What the fit's evaluations depend on (the key of its cache), the pilot's numerics
        included."""
        p = self.points
        return {"kind": "points", "scene": self.scene, "overrides": self.overrides,
                "params": [(q.key, q.lo, q.hi) for q in self.params], "configs": self.configs,
                "velocities": self.velocities.tolist(), "data": [p.force.tolist(), p.force_sd.tolist(),
                                                                  p.speed.tolist(), p.speed_sd.tolist()],
                "pilot": self.pilot.spec()}

    def numerics(self, theta) -> dict:
        """The fit's numerics at ``theta`` (its result), rig.fit.evaluate.numerics."""
        return numerics(self.pilot, self.shots(theta, self.pilot.window_s))

    def start(self) -> np.ndarray:
        return self._start

    @property
    def n_data(self) -> int:
        """The measured values the fit compares: one speed per point."""
        return self.points.n

    @property
    def data_name(self) -> str:
        return f"--points {self.points.source}"

    def candidate_overrides(self, theta, config) -> list:
        return self.overrides + [q.override(x) for q, x in zip(self.params, theta)] + list(config)

    def evaluate(self, thetas: list) -> list:
        cands = [self.candidate_overrides(t, c) for t in thetas for c in self.configs]
        flat = curves(self.scene, cands, self.velocities, self.pilot)
        C = len(self.configs)
        return [tuple(flat[i * C:(i + 1) * C]) for i in range(len(thetas))]

    @staticmethod
    def pack(model) -> dict:
        """The curves' arrays; their gauge readings and F_0 where every curve has them."""
        out = {"velocity": model[0].velocity, "force": np.array([c.force for c in model]),
               "speed": np.array([c.speed for c in model])}
        if all(c.reading is not None and c.static_force is not None for c in model):
            out.update({"reading": np.array([c.reading for c in model]),
                        "static_force": np.array([c.static_force for c in model])})
        return out

    @staticmethod
    def unpack(z: dict):
        """The curves of ``pack``'s arrays (readings None where they were not kept)."""
        n = len(z["force"])
        reading, static = z.get("reading", [None] * n), z.get("static_force", [None] * n)
        return tuple(Curve(z["velocity"], f, v, r, f0)
                     for f, v, r, f0 in zip(z["force"], z["speed"], reading, static))

    def model_speeds(self, model) -> tuple:
        """(V_s at each point's F_d, dlnV/dlnF there); nan where its curve is missing."""
        p = self.points
        V, s = np.full(p.n, np.nan), np.full(p.n, np.nan)
        for c, curve in enumerate(model):
            rows = self.config_of == c
            try:
                V[rows], s[rows] = curve.speed_at(p.force[rows])
            except RigError:  # fewer than two pulses on this curve: its points get NO_CURVE
                continue
        return V, s

    def reach(self, model) -> tuple:
        """(F_e, V_e) of each point's curve's largest pulse (module doc)."""
        ends = np.array([c.reach() for c in model])
        return ends[self.config_of, 0], ends[self.config_of, 1]

    def reachable(self, model) -> np.ndarray:
        """Whether a striker velocity of its curve gives each point's amplitude."""
        return self.points.force <= self.reach(model)[0]

    def residuals(self, model, eta) -> np.ndarray:
        p = self.points
        V, s = self.model_speeds(model)
        F_e, V_e = self.reach(model)
        beyond = ~self.reachable(model)
        V = np.where(beyond, V_e, V)
        sd = np.sqrt(p.speed_sd ** 2 + (s * V / np.where(beyond, F_e, p.force) * p.force_sd) ** 2)
        r = (V - p.speed) / sd
        gap = np.where(beyond, (p.force - F_e) / p.force_sd, 0.0)
        r = np.where(beyond, np.where(r >= 0, 1.0, -1.0) * np.hypot(r, gap), r)
        return np.where(np.isfinite(r), r, NO_CURVE)

    def compared_speeds(self, model) -> np.ndarray:
        """The model's V_s (m/s) each point is compared with: the curve's at the point's F_d,
        or, for a point beyond the curve's largest pulse, the curve's end speed."""
        return np.where(self.reachable(model), self.model_speeds(model)[0], self.reach(model)[1])

    def relative_residuals(self, model) -> np.ndarray:
        """V_model(F_i) / V_i - 1 at each point (an unreachable one: the curve's end speed's)."""
        return self.compared_speeds(model) / self.points.speed - 1.0

    def relative_rms(self, model, eta) -> float:
        """RMS of the relative speed residuals (points without a model curve left out)."""
        return float(np.sqrt(np.nanmean(self.relative_residuals(model) ** 2)))

    @staticmethod
    def nuisance_start():
        return np.zeros(0), np.zeros(0), np.zeros(0)

    def nuisance_jacobian(self, model, eta):
        return np.zeros((self.points.n, 0))

    @staticmethod
    def nuisance_report(eta) -> dict:
        return {}
