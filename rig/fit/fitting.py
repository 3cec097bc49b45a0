"""The fit itself: bounded weighted least squares (scipy.optimize.least_squares, trust
region reflective) of an objective's residuals r(theta, eta), theta the scene parameters
(each candidate a virtual shot or curve, expensive) and eta the objective's nuisance
parameters (cheap: no solve).

The Jacobian's theta columns are finite differences, forward or central as the objective
declares (``central_differences``), whose candidates are solved together in one batched
call (rig.fit.evaluate); every evaluation is kept on disk in the fit's
folder, so a fit that is stopped and started again replays what it had done without
solving it again (resume); rig.fit.multistart starts it from several points.
Uncertainties: the covariance (J^T J)^-1 of the normalised
residuals at the solution, scaled by chi^2/dof when that exceeds 1 (the misfit is then
larger than the stated uncertainties explain); 95% intervals estimate +- 1.96 sd, cut at
the bounds. Goodness: chi^2, dof, its p-value, BIC = chi^2 + k ln n.
"""
from __future__ import annotations

import hashlib
import json
import math
import sys
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from scipy import optimize, stats

from instruments.files import atomic_write
from rig.errors import RigError
from rig.fit.checks import IMPLAUSIBLE_P, check_data_count, unseen

FD_STEP = 0.01
"""Finite-difference step, as a fraction of each parameter's bound interval: large enough
that the change of the model stands far above the solver's error (accuracy 1e-4). Where the
model is far from linear over the step (a scope trace, whose pulses move with the
parameters), a forward difference is a secant and not the derivative: the objective then
asks for central differences, whose error falls as the step squared."""
HIGH_CORRELATION = 0.95


@dataclass(frozen=True)
class FitResult:
    """A finished fit: estimates, standard deviations and 95% intervals (SI units, in the
    order of ``keys``), correlation matrix, residuals, goodness and convergence; ``model``:
    the objective's evaluation at the estimate, ``eta`` its nuisance parameters."""

    keys: tuple
    units: tuple
    estimate: np.ndarray
    std: np.ndarray
    ci95: np.ndarray
    correlation: np.ndarray
    residuals: np.ndarray
    chi2: float
    dof: int
    converged: bool
    message: str
    evaluations: int
    at_bound: tuple
    nuisance: dict = field(default_factory=dict)
    eta: np.ndarray = field(default_factory=lambda: np.zeros(0))
    model: Any = None  # the objective's own form of its model at the fit (curves, traces, figures)
    replayed: int = 0  # candidates read back from the cache of an earlier run (evaluations: solved in this one)
    bounds: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))  # (lo, hi) of each parameter, SI
    jacobian: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))  # of the residuals at the estimate,
    # per parameter's bound span and per nuisance parameter (rig.fit.crossval)

    @property
    def chi2_reduced(self) -> float:
        return self.chi2 / self.dof if self.dof > 0 else math.nan

    @property
    def p_value(self) -> float:
        return float(stats.chi2.sf(self.chi2, self.dof)) if self.dof > 0 else math.nan

    @property
    def undetermined(self) -> tuple:
        """The keys whose 95% interval, estimate +- 1.96 sd, reaches past both of their
        bounds: the data do not narrow them inside the bounds (alone, or apart from a
        correlated partner: ``correlated_pairs``); an sd wider than the span always does."""
        return tuple(k for k, e, sd, (lo, hi) in zip(self.keys, self.estimate, self.std, self.bounds)
                     if not (e - 1.96 * sd > lo or e + 1.96 * sd < hi))

    @property
    def usable(self) -> bool:
        """Whether the result stands for the scene: converged, plausible (or nothing to judge
        it by), every parameter determined and none at a bound of its range. Only then is a
        fitted scene written."""
        return self.converged and self.plausible is not False and not self.undetermined and not self.at_bound

    @property
    def interval_scale(self) -> float:
        """The factor the sds and intervals were widened by: sqrt(chi2/dof) where above 1."""
        return math.sqrt(max(1.0, self.chi2_reduced)) if self.dof > 0 else 1.0

    @property
    def plausible(self) -> bool | None:
        """Whether the model can describe the data: chi2's p-value >= IMPLAUSIBLE_P (None
        without degrees of freedom: nothing to judge by)."""
        return None if self.dof <= 0 else self.p_value >= IMPLAUSIBLE_P

    @property
    def bic(self) -> float:
        return self.chi2 + len(self.keys) * math.log(max(self.residuals.size, 1))

    def correlated_pairs(self) -> list:
        """[(key, key, rho)] of parameters whose |correlation| exceeds HIGH_CORRELATION."""
        k = len(self.keys)
        return [(self.keys[i], self.keys[j], float(self.correlation[i, j]))
                for i in range(k) for j in range(i + 1, k) if abs(self.correlation[i, j]) > HIGH_CORRELATION]


class EvaluationCache:
    """Every model evaluation of a fit, in memory and (with a folder) on disk: one .npz
    per candidate, named by the digest of the fit's specification and the candidate."""

    def __init__(self, objective, folder: Path | None):
        self.objective = objective
        self.memory: dict[tuple, object] = {}
        self.folder = None if folder is None else Path(folder)
        self.spec = hashlib.sha256(json.dumps(objective.spec(), sort_keys=True).encode()).hexdigest()[:16]
        self.solved = 0  # candidates solved in this run (not replayed from disk)
        self.replayed = 0  # candidates read back from disk
        if self.folder is not None:
            try:
                self.folder.mkdir(parents=True, exist_ok=True)
            except OSError as exc:
                raise RigError(f"fit cache {self.folder}: cannot create ({exc.strerror})") from None

    def _path(self, key: tuple) -> Path:
        assert self.folder is not None, "only a cache with a folder keeps files"
        digest = hashlib.sha256((self.spec + repr(key)).encode()).hexdigest()[:20]
        return self.folder / f"{digest}.npz"

    def get(self, thetas: list) -> list:
        keys = [tuple(float(x) for x in t) for t in thetas]
        todo = []
        for k in dict.fromkeys(keys):
            if k in self.memory:
                continue
            if self.folder is not None and self._path(k).is_file() and self._replay(k):
                continue
            todo.append(k)
        if todo:
            for k, model in zip(todo, self.objective.evaluate([np.array(k) for k in todo])):
                self.memory[k] = model
                self.solved += 1
                if self.folder is not None:  # whole or not at all: a full disk leaves no broken entry
                    arrays = self.objective.pack(model)
                    atomic_write(self._path(k), lambda tmp, arrays=arrays: _savez(tmp, arrays))
        return [self.memory[k] for k in keys]

    def _replay(self, key: tuple) -> bool:
        """Read a stored candidate back; one that cannot be read (left by an older version
        cut short, or damaged) is dropped with a note on stderr and solved again (False)."""
        path = self._path(key)
        try:
            with np.load(path) as z:
                self.memory[key] = self.objective.unpack({n: z[n] for n in z.files})
        except Exception as exc:  # noqa: BLE001 - any unreadable entry: EOFError, BadZipFile, KeyError, ...
            why = " ".join(f"{type(exc).__name__} {exc}".split())
            print(f"fit cache {path}: unreadable ({why}); dropped, solved again", file=sys.stderr, flush=True)
            path.unlink(missing_ok=True)
            return False
        self.replayed += 1
        return True


def difference_steps(x: np.ndarray, central: bool) -> tuple:
    """The steps (up, down) of each normalised parameter x (in [0, 1]) for its Jacobian
    column (r(x + up) - r(x + down)) / (up - down): central (+-FD_STEP) where asked and both
    fit within the bounds, else forward (down 0), backward at the upper bound."""
    up = np.where(x + FD_STEP <= 1.0, FD_STEP, -FD_STEP)
    down = np.where(central & (x - FD_STEP >= 0.0) & (up > 0), -FD_STEP, 0.0)
    return up, down


def fit(objective, cache_folder=None, max_evaluations: int = 400, progress=None, ftol: float = 1e-8,
        xtol: float = 1e-6, start=None) -> FitResult:
    """Fit ``objective`` (rig.fit.points.PointObjective, rig.fit.traces.TraceObjective,
    rig.fit.observations.objective.ObservationObjective, rig.fit.joint.JointObjective); it
    stops where a step changes chi2 by less than the fraction ``ftol`` or the normalised
    parameters by less than about ``xtol`` (scipy.optimize.least_squares). ``start``: the
    parameters' start (SI; default the objective's own)."""
    params = objective.params
    P = len(params)
    lo = np.array([p.lo for p in params])
    span = np.array([p.hi - p.lo for p in params])
    eta0, eta_lo, eta_hi = objective.nuisance_start()
    check_data_count(objective.n_data, P, eta0.size, objective.data_name)
    theta0 = objective.start() if start is None else np.asarray(start, dtype=float)
    x0 = np.concatenate((np.clip((theta0 - lo) / span, 0.0, 1.0), eta0))
    bounds = (np.concatenate((np.zeros(P), eta_lo)), np.concatenate((np.ones(P), eta_hi)))
    cache = EvaluationCache(objective, cache_folder)
    tell = progress or (lambda text: None)
    count = {"batches": 0}

    def theta(x):
        return lo + span * x[:P]

    def fun(x):
        (model,) = cache.get([theta(x)])
        return objective.residuals(model, x[P:])

    def jac(x):
        up, down = difference_steps(x[:P], objective.central_differences)
        eye = np.eye(x.size)[:P]
        cands = [theta(x)] + [theta(x + h * e) for h, e in zip(up, eye)] + [theta(x + h * e) for h, e in zip(down, eye)]
        models = cache.get(cands)
        count["batches"] += 1
        r0 = objective.residuals(models[0], x[P:])
        J = np.empty((r0.size, x.size))
        for k in range(P):
            below = objective.residuals(models[1 + P + k], x[P:]) if down[k] else r0
            J[:, k] = (objective.residuals(models[1 + k], x[P:]) - below) / (up[k] - down[k])
        J[:, P:] = objective.nuisance_jacobian(models[0], x[P:])
        if count["batches"] == 1:
            unseen(params, J)  # at the start: before the optimiser spends evaluations on it
        tell(f"fit: Jacobian {count['batches']}: chi2 {float(r0 @ r0):.6g}, "
             + ", ".join(p.key + " " + p.shown(v) for p, v in zip(params, theta(x)))
             + f" ({cache.solved} candidates solved)")
        return J

    res = optimize.least_squares(fun, x0, jac=jac, bounds=bounds, method="trf", x_scale="jac",
                                 max_nfev=max_evaluations, xtol=xtol, ftol=ftol, gtol=1e-8)
    (model,) = cache.get([theta(res.x)])
    r = objective.residuals(model, res.x[P:])
    J = jac(res.x)
    chi2 = float(r @ r)
    dof = int(r.size - x0.size)
    cov_n = np.linalg.pinv(J.T @ J)
    cov_n = cov_n * max(1.0, chi2 / dof if dof > 0 else 1.0)
    sd_n = np.sqrt(np.clip(np.diag(cov_n)[:P], 0.0, None))
    est = theta(res.x)
    std = np.where(np.any(J[:, :P], axis=0), sd_n * span, math.inf)  # a zero column: no information, not sd 0
    with np.errstate(invalid="ignore", divide="ignore"):
        corr = cov_n[:P, :P] / np.outer(sd_n, sd_n)
    ci = np.column_stack((np.maximum(est - 1.96 * std, lo), np.minimum(est + 1.96 * std, lo + span)))
    at_bound = tuple(p.key for p, x in zip(params, res.x[:P]) if x <= 1e-6 or x >= 1 - 1e-6)
    converged = bool(res.success and res.status > 0 and np.all(np.isfinite(std)))
    return FitResult(tuple(p.key for p in params), tuple(p.unit for p in params), est, std, ci, corr, r, chi2, dof,
                     converged, str(res.message), cache.solved, at_bound, objective.nuisance_report(res.x[P:]),
                     res.x[P:].copy(), model, cache.replayed, np.column_stack((lo, lo + span)), J)


def _savez(path, arrays: dict):
    with open(path, "wb") as fh:  # a handle: np.savez would add ".npz" to a name without it
        np.savez(fh, **arrays)


def stderr_progress(text: str):
    print(text, file=sys.stderr, flush=True)
