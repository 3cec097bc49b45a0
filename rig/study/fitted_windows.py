"""Where the kept set of `rig reproduce daraio2006 --fitted` still meets every target: each
fitted parameter's one-dimensional window, the others held at the set.

Every Table 1 and Fig. 3 target (rig.study.reproduce_fitted_report.observed_targets: Table
1's chi2/dof, relative RMS, worst point in sd and reach; Fig. 3's speeds, duration, train,
gauge ratio, wall and tail) is judged at a candidate from its Table 1 curves (rig.fit.points)
and its two Fig. 3 shots at 0.89 m/s, every candidate's shots solved in one batch at pilots
calibrated at the set. A parameter's window: a scan of SCAN_POINTS values evenly in ln p
over the family's bounds, then bisection in ln p of each edge to RESOLUTION
(rig.study.sensitivity.window), each edge naming the targets that fail just past it.
"""
from __future__ import annotations

import math

import numpy as np

from rig.fit.evaluate import solve_rigs
from rig.fit.observations.objective import ObservationObjective
from rig.fit.parameters import parse_parameters
from rig.fit.points import PointObjective
from rig.study.fitted_families import SCENE, Family, with_magnetic
from rig.study.fitted_shots import fig3_figures
from rig.study.reproduce_fitted_report import misses
from rig.study.sensitivity import window

SCAN_POINTS = 9
RESOLUTION = 0.002
"""A window's edge is bisected until its passing and failing values differ by 0.2% (in ln p)."""


class Targets:
    """The targets a family's parameter sets meet (module doc), with the pilots calibrated
    at ``theta`` (SI, the family's parameters' order)."""

    def __init__(self, family: Family, points, observations, theta):
        self.params = parse_parameters(family.params)
        points, observations = with_magnetic(family, points, observations)
        self.curves = PointObjective(SCENE, self.params, points, family.fixed, theta)
        self.shots = ObservationObjective(SCENE, self.params, observations, family.fixed, "Fig. 3", theta)

    def table1(self, model) -> dict:
        """Table 1's target figures of one candidate's curves."""
        c = self.curves
        r = c.residuals(model, np.zeros(0))
        rel = c.relative_residuals(model)
        dof = r.size - len(self.params)
        return {"table1_chi2_per_dof": float(r @ r) / dof if dof > 0 else math.nan,
                "table1_rms_relative": float(np.sqrt(np.nanmean(rel ** 2))),
                "table1_max_sigma": float(np.max(np.abs(r))),
                "table1_unreachable": int(np.count_nonzero(~c.reachable(model)))}

    def rows(self, thetas) -> list:
        """Each candidate's figures: Table 1's (table1) and "fig3" (rig.study.fitted_shots.fig3_figures;
        {} where a shot blew up or the scene refused it)."""
        models = self.curves.evaluate([np.asarray(t, float) for t in thetas])
        rigs = [self.shots.rigs_of(t) for t in thetas]
        flat = [r for rs in rigs for r in rs if r is not None]
        solved = dict(zip(map(id, flat), solve_rigs(flat, self.shots.pilot)))
        out = []
        for model, rs in zip(models, rigs):
            good = all(r is not None and solved[id(r)] for r in rs)
            truths = {s.scene: r.truth() for s, r in zip(self.shots.shot_list, rs)} if good else None
            out.append(self.table1(model) | {"fig3": fig3_figures(truths) if truths else {}})
        return out

    def missed(self, thetas) -> list:
        """For each candidate, the names of the targets it misses (empty: it meets them all)."""
        return [tuple(m["target"] for m in misses(row)) for row in self.rows(thetas)]


def windows(targets: Targets, theta, progress=None) -> dict:
    """{key: {"value", "unit", "window": [lo, hi] or None, "relative": [lo / value - 1, hi /
    value - 1], "open": [bool, bool], "failing_below", "failing_above", "scan": [lo, hi]}} of
    each fitted parameter at the set ``theta`` (module doc; a bound at 0 scanned from a
    hundredth of the value); window None where the set itself misses a target (its figures
    here differ from the fit's by the pilots' steps) or the value is 0."""
    tell = progress or (lambda text: None)
    theta = np.asarray(theta, float)
    out = {}
    for k, p in enumerate(targets.params):
        def holds(values, k=k):
            cands = []
            for v in values:
                t = theta.copy()
                t[k] = v
                cands.append(t)
            return targets.missed(cands)

        value = float(theta[k])
        scan = [p.lo if p.lo > 0 else value / 100.0, p.hi]  # ln p: a bound at 0 scanned from a hundredth
        edges = window(holds, value, scan[0], scan[1], SCAN_POINTS, RESOLUTION) if value > 0 else None
        row: dict = {"value": value, "unit": p.unit, "scan": scan}
        if edges is None:
            row.update(window=None, relative=None, open=None, failing_below=None, failing_above=None)
        else:
            lo, hi = edges
            row.update(window=[lo.value, hi.value], relative=[lo.value / value - 1.0, hi.value / value - 1.0],
                       open=[lo.open, hi.open], failing_below=list(lo.failing), failing_above=list(hi.failing))
        out[p.key] = row
        tell(f"window of {p.key}")
    return out
