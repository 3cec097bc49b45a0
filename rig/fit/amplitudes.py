"""Measured (F_d, V_s) points compared two ways: through the model's contact forces and
through the paper's elastic conversion of the model's gauge readings.

Daraio et al. (2006) obtained each measured F_d from their gauges' readings F_m,e by the
elastic (Hertz) solitary wave's conversion F_d = beta(F_m/F_0) F_m,e, F_m = F_d + F_0
(rig.theory.solitary.elastic_amplitude). A model's curve V_s(F_d) (rig.fit.evaluate.Curve)
takes F_d from the model's own contact forces, the largest dynamic contact force at the
gauge beads (the truth analysis): (1), what a fit compares. Where the model's contacts are
not elastic (they yield, they dissipate), its gauge beads' readings convert to another F_d
than its contact forces give. (2) takes the model's F_d as the paper took the experiment's:
the same shots' readings, converted. Each point's model V_s at its F_d on both curves, and
its residual in standard deviations as the fit counts it (rig.fit.points.PointObjective.
residuals: effective variance; a point beyond the curve's largest pulse measured from the
curve's end), and chi2 per (points - fitted parameters) each way.
"""
from __future__ import annotations

import math

import numpy as np

from rig.errors import RigError
from rig.fit.evaluate import Curve
from rig.theory.solitary import elastic_amplitude

ELASTIC_EXPONENT = 1.5
"""The contact exponent of the paper's conversion: its numerics were of Hertz's law."""
CONTACT, ELASTIC = "contact_force", "elastic_conversion"
"""The two ways, as the keys name them."""


def elastic_curve(curve: Curve, n: float = ELASTIC_EXPONENT) -> Curve:
    """The curve (velocity, F_d, V_s) with F_d the elastic conversion of each shot's gauge
    reading at its F_0 (module doc): nan where a shot gave no reading or one whose F_m/F_0
    lies below beta's range (rig.theory.solitary.MIN_FORCE_RATIO). RigError where the curve
    holds no readings."""
    if curve.reading is None or curve.static_force is None:
        raise RigError("the model's curve holds no gauge readings (read back from a store that did not keep them)")
    F = np.full(curve.reading.shape, math.nan)
    for k, (reading, F0) in enumerate(zip(curve.reading, curve.static_force)):
        if math.isfinite(reading) and reading > 0 and math.isfinite(F0):
            try:
                F[k] = elastic_amplitude(float(reading), float(F0), n)
            except RigError:  # below beta's range of F_m/F_0: no point on this curve
                continue
    return Curve(curve.velocity, F, curve.speed)


def _num(x) -> float | None:
    return float(x) if x is not None and math.isfinite(x) else None


def _way(part, model) -> tuple:
    """(V_s compared at each point, residuals in sd, reachable, relative RMS) of one way, as
    the fit counts them (rig.fit.points.PointObjective)."""
    return (part.compared_speeds(model), part.residuals(model, np.zeros(0)), part.reachable(model),
            part.relative_rms(model, np.zeros(0)))


def both_conversions(part, model, fitted: int) -> dict:
    """The points of ``part`` (a rig.fit.points.PointObjective) against ``model`` (its
    curves, with their readings) both ways (module doc), ``fitted`` the number of fitted
    parameters (dof = points - fitted): per point its F_d, V_s and their sd, its
    configuration, the model's V_s and the residual (sd) each way and whether the curve
    reaches it; chi2, chi2 per dof and RMS of the relative residuals each way; and each
    configuration's curve: per striker velocity the contact F_d, the reading F_m,e, F_0,
    the converted F_d and V_s."""
    elastic = tuple(elastic_curve(c) for c in model)
    p = part.points
    ways = {CONTACT: _way(part, model), ELASTIC: _way(part, elastic)}
    dof = p.n - fitted
    points = []
    for i in range(p.n):
        row = {"F_d_N": float(p.force[i]), "F_d_sd_N": float(p.force_sd[i]), "V_s_m_per_s": float(p.speed[i]),
               "V_s_sd_m_per_s": float(p.speed_sd[i]), "configuration": list(p.configs[i])}
        for name, (V, r, reach, _) in ways.items():
            row.update({f"model_V_s_{name}_m_per_s": _num(V[i]), f"residual_{name}_sd": _num(r[i]),
                        f"reachable_{name}": bool(reach[i])})
        points.append(row)
    out: dict = {"fit_uses": CONTACT, "elastic_exponent": ELASTIC_EXPONENT, "dof": dof, "points": points}
    for name, (_, r, _, rms) in ways.items():
        chi2 = float(r @ r)
        out.update({f"chi2_{name}": chi2, f"chi2_per_dof_{name}": chi2 / dof if dof > 0 else None,
                    f"rms_relative_{name}": _num(rms)})
    out["curves"] = [{"configuration": list(cfg), "velocity_m_per_s": [float(v) for v in c.velocity],
                      "contact_force_N": [_num(x) for x in c.force], "reading_N": [_num(x) for x in c.reading],
                      "static_force_N": [_num(x) for x in c.static_force],
                      "elastic_conversion_N": [_num(x) for x in e.force], "speed_m_per_s": [_num(x) for x in c.speed]}
                     for cfg, c, e in zip(part.configs, model, elastic)]
    return out
