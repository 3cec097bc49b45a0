"""One model family judged on the published experiment: fitted jointly to Table 1 and
Fig. 3's observations, and asked to predict data it was not fitted to.

- Table 1, leave one out: each point's residual predicted by the fit to the others, the
  linearised leave-one-out of rig.fit.crossval (r_i / (1 - h_ii), h the hat matrix of the
  joint fit's normalised Jacobian at its optimum; exact for a linear model; ten exact
  refits per family would cost more than the command's budget).
- Magnetic from gravity: the family fitted to the gravity-only data (Table 1's gravity
  points and Fig. 3's gravity observations) predicts the magnetic data (points and
  observations): their chi2 and the RMS of their relative residuals.

Both are sums of squared normalised residuals of held-out data; the family kept is the one
whose sum of the two is lowest.
"""
from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from rig.errors import RigError
from rig.fit.amplitudes import both_conversions
from rig.fit.checks import unusable
from rig.fit.crossval import leverages
from rig.fit.fitting import FitResult, fit
from rig.fit.globalsearch import optima_block, searched_fit
from rig.study.fitted_bounds import SOURCES
from rig.study.fitted_families import (
    Family,
    fitted_overrides,
    magnetic_observation,
    magnetic_points,
    objective,
    unavailable,
)

FTOL, XTOL = 1e-2, 1e-3
"""Where a family's fits stop: a step that changes chi2 by less than 1% (below the change
of 1 that moves an interval, for any chi2 below 100) or the parameters by less than 1e-3 of their bounds'
span (a tenth of the Jacobian's step): tighter, they spend solves on the solver's
noise (rig.fit.fitting's defaults are 1e-8 and 1e-6)."""


@dataclass(frozen=True)
class SearchPlan:
    """How each family's joint fit looks for its optimum: ``starts`` local fits
    (rig.fit.multistart), after a global search of ``generations`` generations drawn from
    ``seed`` where > 0 (rig.fit.globalsearch); every evaluation cached under ``folder`` (a
    family's own folder in it: a run stopped and started again replays them; None: in memory);
    ``detail`` told each fit's and search's progress lines."""

    starts: int = 1
    generations: int = 0
    seed: int = 0
    folder: Path | None = None
    detail: Callable | None = None

    def cache(self, family: Family) -> Path | None:
        """The family's evaluation cache folder."""
        return None if self.folder is None else self.folder / "".join(c if c.isalnum() else "_" for c in family.name)


@dataclass(frozen=True)
class Assessment:
    """A family's verdict: ``row`` its JSON row (rig reproduce's "models"); ``result`` its
    joint fit (None where skipped or failed); ``overrides`` every shot's overrides at its
    estimate."""

    family: Family
    row: dict
    result: FitResult | None = None
    overrides: tuple = ()

    @property
    def held_out_chi2(self) -> float:
        """Leave-one-out chi2 of Table 1 plus the magnetic data's chi2 predicted from gravity
        (nan where either is missing)."""
        return self.row.get("held_out_chi2", math.nan)


def parameters(result: FitResult) -> dict:
    """{key: {"estimate", "std", "ci95", "unit"}} of a fit (SI)."""
    return {k: {"estimate": float(e), "std": float(s), "ci95": [float(a), float(b)], "unit": u}
            for k, u, e, s, (a, b) in zip(result.keys, result.units, result.estimate, result.std, result.ci95)}


def _rms(x) -> float:
    x = np.asarray(x, dtype=float)
    x = x[np.isfinite(x)]
    return float(np.sqrt(np.mean(x ** 2))) if x.size else math.nan


def table1_figures(obj, result: FitResult) -> dict:
    """Table 1's share of a joint fit (its first part): chi2 per (points - fitted parameters),
    relative RMS and worst point, the largest |residual| in sd, the points no striker velocity
    of the model's curve reaches (rig.fit.points), the linearised leave-one-out
    (rig.fit.crossval), and the points against the model's F_d both ways, its contact forces
    (what the fit compares) and the paper's elastic conversion of its gauge readings
    (rig.fit.amplitudes: "table1_points_both_conversions")."""
    rows = obj.slices[0]
    r = result.residuals[rows]
    rel = obj.parts[0].relative_residuals(result.model[0])
    h = leverages(result.jacobian)[rows]
    keep = 1.0 - h
    loo_r, loo_rel = r / keep, rel / keep
    dof = r.size - len(result.keys)
    reach = obj.parts[0].reachable(result.model[0])
    return {"table1_unreachable": int(np.count_nonzero(~reach)), "table1_reachable": reach.tolist(),
            "table1_chi2": float(r @ r), "table1_chi2_per_dof": float(r @ r) / dof if dof > 0 else math.nan,
            "table1_rms_relative": _rms(rel), "table1_max_sigma": float(np.max(np.abs(r))),
            "rms_relative": _rms(rel), "max_relative": float(np.nanmax(np.abs(rel))),
            "relative_residuals": rel.tolist(), "normalised_residuals": r.tolist(),
            "loo_method": "linearised (PRESS: r_i / (1 - h_ii) at the joint optimum)",
            "loo_chi2": float(loo_r @ loo_r), "loo_rms_relative": _rms(loo_rel),
            "loo_relative_residuals": loo_rel.tolist(),
            "table1_points_both_conversions": both_conversions(obj.parts[0], _with_readings(obj, result),
                                                               len(result.keys))}


def _with_readings(obj, result: FitResult) -> tuple:
    """Table 1's curves at the fit's estimate with their gauge readings: the fit's own, or,
    where they were read back from a store that did not keep the readings, its Table 1
    shots solved again."""
    model = result.model[0]
    if all(c.reading is not None for c in model):
        return model
    return obj.parts[0].evaluate([result.estimate])[0]


def estimates(result: FitResult) -> dict:
    """{key: estimate (SI)} of a fit."""
    return {k: float(e) for k, e in zip(result.keys, result.estimate)}


def magnetic_from_gravity(family: Family, points, observations, joint: FitResult) -> dict:
    """The family fitted to the gravity-only data (starting at its ``joint`` fit's values),
    predicting the magnetic data (module doc): its magnetic-only keys at the law's defaults
    ("at_defaults"); a key the gravity-only data do not see (rig.fit.checks.unseen) held at
    the joint fit's value ("held_at_joint": the law may need it, a yield pressure)."""
    mag_p = magnetic_points(points)
    mag_o = [magnetic_observation(o) for o in observations]
    gravity = family.without(family.magnetic_only)  # keys only the magnet's shots see: at the law's defaults
    joint_values = estimates(joint)
    held: dict = {}
    while True:  # and the keys the gravity-only data do not see, held at the joint fit's values
        g_obj = objective(gravity, points.subset(np.flatnonzero(~mag_p)),
                          tuple(o for o, m in zip(observations, mag_o) if not m), joint_values)
        try:
            g = fit(g_obj, ftol=FTOL, xtol=XTOL)
            break
        except RigError as exc:
            key = next((p.split("=")[0] for p in gravity.params if f"'{p.split('=')[0]}'" in str(exc)), None)
            if "do not see it" not in str(exc) or key is None or len(gravity.params) == 1:
                raise
            held[key] = joint_values[key]
            gravity = dataclasses.replace(gravity.without((key,)),
                                          fixed=gravity.fixed + (f"{key}={joint_values[key]!r}",))
    m_obj = objective(gravity, points.subset(np.flatnonzero(mag_p)),
                      tuple(o for o, m in zip(observations, mag_o) if m))
    (model,) = m_obj.evaluate([g.estimate])
    r = m_obj.residuals(model, np.zeros(0))
    return {"parameters": parameters(g), "at_defaults": list(family.magnetic_only), "held_at_joint": held,
            "converged": g.converged, "chi2": float(r @ r), "n": int(r.size),
            "chi2_per_point": float(r @ r) / r.size, "rms_relative": m_obj.relative_rms(model, np.zeros(0))}


def assess(family: Family, points, observations, tell, done=(), search: SearchPlan | None = None) -> Assessment:
    """The family's joint fit and held-out prediction (module doc), its fit starting where
    the Assessment in ``done`` of the family it starts from ended (else at the family's own
    start), through ``search`` (the starts, the global search, the cache); a family this
    version cannot fit is skipped, one whose fit the rig refuses is failed, each with the
    reason."""
    search = search or SearchPlan()
    row: dict = {"note": family.note, "fitted_keys": list(family.params), "fixed": list(family.fixed),
           "magnetic_only": list(family.magnetic), "skipped": unavailable(family) or None, "failed": None,
           "bounds_sources": {p.split("=")[0]: SOURCES.get(p.split("=")[0]) for p in family.params}}
    if row["skipped"]:
        tell(f"{family.name}: skipped")
        return Assessment(family, row)
    try:
        parent = next((a.result for a in done if a.family.name == family.starts_from and a.result), None)
        start = dict(family.start) | ({} if parent is None else estimates(parent))
        obj = objective(family, points, observations, start)
        r, optima, found = searched_fit(obj, search.starts, search.generations, search.seed, search.cache(family),
                                        progress=search.detail, ftol=FTOL, xtol=XTOL)
    except RigError as exc:
        row["failed"] = f"joint fit: {exc}"
        tell(f"{family.name}: failed")
        return Assessment(family, row)
    row.update({"parameters": parameters(r), "chi2": r.chi2, "dof": r.dof, "bic": r.bic, "converged": r.converged,
                "candidates_solved": r.evaluations, "candidates_replayed": r.replayed,
                "optima": optima_block(r, optima),
                "at_bound": list(r.at_bound), "unusable": unusable(r) or None,
                "fig3_chi2": float(np.sum(r.residuals[obj.slices[1]] ** 2)), **table1_figures(obj, r)})
    if found is not None:
        row["global_search"] = found.as_dict(r.keys)
    tell(f"{family.name}: joint fit")
    try:
        row["magnetic_from_gravity"] = magnetic_from_gravity(family, points, observations, r)
        row["held_out_chi2"] = row["loo_chi2"] + row["magnetic_from_gravity"]["chi2"]
    except RigError as exc:
        row["magnetic_from_gravity"] = {"failed": str(exc)}
    tell(f"{family.name}: magnetic from gravity")
    return Assessment(family, row, r, tuple(fitted_overrides(family, r)))


def choose(assessments: list) -> Assessment | None:
    """The family that predicts held-out data best (lowest held_out_chi2) among those whose
    joint fit converged; None where none did."""
    ok = [a for a in assessments if a.result is not None and a.result.converged and math.isfinite(a.held_out_chi2)]
    return min(ok, key=lambda a: a.held_out_chi2) if ok else None
