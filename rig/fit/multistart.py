"""A fit started from several points, to find a narrow window or the right one of two
minima (rig fit --starts N): the objective's own start, then any seeds (a global search's
best members, rig.fit.globalsearch), then points a Kronecker sequence spreads over the
bounds; each start is rig.fit.fitting.fit, all of them sharing one
evaluation cache, and every distinct optimum is reported beside the best."""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from rig.fit.fitting import fit

DISTINCT = 0.01  # optima closer than this fraction of every parameter's range are one


def start_points(objective, starts: int, seeds=()) -> list:
    """``starts`` starts (SI), at least 1 + len(seeds): the objective's own (the scene's value
    where the scene sets the key inside the bounds, else the bounds' middle), then ``seeds``
    (SI: a global search's best members, rig.fit.globalsearch), then points spread over the bounds by a
    Kronecker sequence (x_i = frac(1/2 + i a_j) in each parameter's normalised range, a_j
    the powers of the generalised golden ratio: every start is new and the starts fill the
    box evenly; deterministic, so a fit run again starts from the same points)."""
    params = objective.params
    P = len(params)
    lo = np.array([p.lo for p in params])
    span = np.array([p.hi - p.lo for p in params])
    phi = 2.0
    for _ in range(64):  # the generalised golden ratio: phi^(P+1) = phi + 1
        phi = (1.0 + phi) ** (1.0 / (P + 1))
    alpha = (1.0 / phi) ** np.arange(1, P + 1)
    out = [np.asarray(objective.start(), dtype=float)] + [np.asarray(s, dtype=float) for s in seeds]
    for i in range(1, starts - len(out) + 1):
        out.append(lo + span * np.mod(0.5 + i * alpha, 1.0))
    return out


@dataclass(frozen=True)
class Optimum:
    """One distinct optimum a multi-start fit found: its estimate (SI), chi2, whether its
    fit converged, and the starts (SI) that reached it."""

    estimate: tuple
    chi2: float
    converged: bool
    starts: tuple


def multistart(objective, starts: int, cache_folder=None, max_evaluations: int = 400, progress=None, seeds=(),
               ftol: float = 1e-8, xtol: float = 1e-6) -> tuple:
    """(the best FitResult, its evaluations and replayed counts those of every start, and
    the Optimum list): ``fit`` from each of ``start_points``; the optima found, distinct
    where some parameter differs by more than DISTINCT of its range, best first (lowest
    chi2 of the converged fits, then of the others). Every evaluation shares
    ``cache_folder``: a run stopped and started again replays what it had solved. One start
    is ``fit`` itself; ``seeds`` are starts after the objective's own (start_points);
    ``ftol``, ``xtol`` each fit's stopping rule (rig.fit.fitting.fit)."""
    tell = progress or (lambda text: None)
    span = np.array([p.hi - p.lo for p in objective.params])
    results = []
    points = start_points(objective, starts, seeds)
    for k, theta0 in enumerate(points):
        if len(points) > 1:
            tell(f"fit: start {k + 1} of {len(points)} at " + ", ".join(
                p.key + " " + p.shown(v) for p, v in zip(objective.params, theta0)))
        results.append((theta0, fit(objective, cache_folder, max_evaluations, progress, ftol, xtol, theta0)))
    ranked = sorted(results, key=lambda tr: (not tr[1].converged, tr[1].chi2))
    best = replace(ranked[0][1], evaluations=sum(r.evaluations for _, r in results),
                   replayed=sum(r.replayed for _, r in results))  # what every start solved and replayed
    optima: list = []
    for theta0, r in ranked:
        same = next((i for i, o in enumerate(optima)
                     if np.all(np.abs(np.array(o.estimate) - r.estimate) <= DISTINCT * span)), None)
        if same is None:
            optima.append(Optimum(tuple(float(x) for x in r.estimate), r.chi2, r.converged,
                                  (tuple(float(x) for x in theta0),)))
        else:
            o = optima[same]
            optima[same] = Optimum(o.estimate, o.chi2, o.converged, o.starts + (tuple(float(x) for x in theta0),))
    return best, optima
