"""A global search of a fit's parameter space before its local fit (rig fit --global-search,
rig reproduce daraio2006 --fitted --global-search): differential evolution (Storn & Price,
J. Global Optim. 11, 341 (1997); scipy.optimize.differential_evolution, strategy best1bin)
of the objective's chi2 over the parameters' bounds, its population drawn from a recorded
seed and its first member the objective's own start. A generation's candidates are solved
in one batched call through the fit's evaluation cache (rig.fit.fitting.EvaluationCache):
a search stopped and run again with the same seed meets the same candidates, replays those
it had solved and goes on where it stopped. Each generation's best is told on the progress
line. The local fits then start from the best distinct members of the last population
(rig.fit.multistart), and every distinct optimum is reported.
"""
from __future__ import annotations

import inspect
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy import optimize

from rig.fit.fitting import EvaluationCache

POPULATION = 10
"""Members per fitted parameter (scipy's popsize)."""
TOLERANCE = 0.01
"""The search stops early where the population's chi2 spread falls below this fraction of
its mean (scipy's tol): the members have gathered in one basin."""


@dataclass(frozen=True)
class Search:
    """What a global search did: its seed, the generations run (the initial population is
    generation 0) and allowed, the candidates it met (``solved`` of them in this run, the
    rest replayed from the cache), the best candidate (SI) and its chi2, each generation's
    best chi2, and the last population (SI) best first with its chi2."""

    seed: int
    generations: int
    max_generations: int
    candidates: int
    solved: int
    best: tuple
    best_chi2: float
    history: tuple
    population: tuple
    population_chi2: tuple

    def as_dict(self, keys) -> dict:
        """fit.json's "global_search" block (SI; ``keys`` the parameters' names)."""
        return {"method": "differential evolution (scipy, best1bin)", "seed": self.seed,
                "generations": self.generations, "max_generations": self.max_generations,
                "population": len(self.population), "candidates": self.candidates,
                "candidates_solved": self.solved, "best": dict(zip(keys, self.best)), "best_chi2": self.best_chi2,
                "best_chi2_per_generation": list(self.history)}


def _seed_keyword() -> str:
    """scipy's name for differential_evolution's random source (``rng`` from 1.15, ``seed`` before)."""
    return "rng" if "rng" in inspect.signature(optimize.differential_evolution).parameters else "seed"


def search(objective, generations: int, seed: int = 0, cache_folder=None, progress=None,
           population: int = POPULATION) -> Search:
    """Differential evolution of ``objective``'s chi2 over its parameters' bounds for at most
    ``generations`` generations after the initial population (module doc); candidates
    through ``cache_folder``'s evaluation cache (None: in memory only)."""
    params = objective.params
    P = len(params)
    lo = np.array([p.lo for p in params])
    span = np.array([p.hi - p.lo for p in params])
    cache = EvaluationCache(objective, cache_folder)
    tell = progress or (lambda text: None)
    seen: dict = {}
    history: list = []
    eta = objective.nuisance_start()[0]

    def chi2(x):  # x: (P, S), the generation's members in [0, 1]
        thetas = [lo + span * np.clip(col, 0.0, 1.0) for col in np.atleast_2d(x.T)]
        values = []
        for t, model in zip(thetas, cache.get(thetas)):
            r = objective.residuals(model, eta)
            values.append(float(r @ r))
            seen[tuple(float(v) for v in t)] = values[-1]
        best = min(seen.items(), key=lambda kv: kv[1])
        history.append(best[1])
        tell(f"global search: generation {len(history) - 1} of at most {generations}: best chi2 {best[1]:.6g} at "
             + ", ".join(p.key + " " + p.shown(v) for p, v in zip(params, best[0]))
             + f" ({cache.solved} candidates solved, {cache.replayed} replayed)")
        return np.array(values)

    x0 = np.clip((np.asarray(objective.start(), float) - lo) / span, 0.0, 1.0)
    draws: dict[str, Any] = {_seed_keyword(): np.random.default_rng(seed)}
    res = optimize.differential_evolution(
        chi2, optimize.Bounds(np.zeros(P), np.ones(P)), maxiter=generations, popsize=population, tol=TOLERANCE,
        polish=False, init="latinhypercube", x0=x0, vectorized=True, updating="deferred", **draws)
    pop = np.asarray(res.population)
    energies = np.asarray(res.population_energies)
    order = np.argsort(energies, kind="stable")
    best_theta, best_chi2 = min(seen.items(), key=lambda kv: kv[1])
    return Search(seed, len(history) - 1, generations, len(seen), cache.solved, best_theta, best_chi2,
                  tuple(history), tuple(tuple(float(v) for v in lo + span * pop[i]) for i in order),
                  tuple(float(energies[i]) for i in order))


def distinct_members(found: Search, params, count: int, distinct: float) -> list:
    """Up to ``count`` members of the last population (SI), best first, each differing from
    every one taken before by more than ``distinct`` of some parameter's range."""
    span = np.array([p.hi - p.lo for p in params])
    out: list = []
    for theta in found.population:
        t = np.array(theta)
        if all(np.any(np.abs(t - o) > distinct * span) for o in out):
            out.append(t)
        if len(out) == count:
            break
    return out


def searched_fit(objective, starts: int = 1, generations: int = 0, seed: int = 0, cache_folder=None,
                 max_evaluations: int = 400, progress=None, ftol: float = 1e-8, xtol: float = 1e-6) -> tuple:
    """(the best FitResult, the distinct optima, the Search or None): with ``generations`` > 0
    the global search first (module doc), then the local fits (rig.fit.multistart) from the
    objective's own start and the search's best distinct members (``starts`` - 1 of them, at
    least one); without, the multi-start fit alone. Every evaluation through ``cache_folder``."""
    from rig.fit.multistart import DISTINCT, multistart

    found, seeds = None, []
    if generations > 0:
        found = search(objective, generations, seed, cache_folder, progress)
        seeds = distinct_members(found, objective.params, max(1, starts - 1), DISTINCT)
    result, optima = multistart(objective, starts, cache_folder, max_evaluations, progress, seeds, ftol, xtol)
    return result, optima, found


def optima_block(result, optima) -> list:
    """fit.json's "optima": each distinct optimum's estimate, chi2, whether its fit
    converged and the starts that reached it (SI, with the parameters' units)."""
    units = dict(zip(result.keys, result.units))
    return [{"estimate": dict(zip(result.keys, o.estimate)), "unit": units, "chi2": o.chi2, "converged": o.converged,
             "starts": [dict(zip(result.keys, s)) for s in o.starts]} for o in optima]
