"""Sobol designs and indices of a study (SALib, an optional extra: pip install ".[sobol]"):
shots in SALib's Sobol design of base x (K + 2) shots, first-order and total indices."""
from __future__ import annotations

import functools
import math

import numpy as np

from rig.errors import RigError, invalid
from rig.study.mc_spec import MonteCarloSpec


def sobol_shots(requested: int, n_inputs: int) -> int:
    """Shots of a Sobol design: base x (K + 2), the base the largest power of 2 that fits."""
    base = 2 ** int(math.floor(math.log2(max(1, requested // (n_inputs + 2)))))
    if base < 8:
        raise invalid("--shots", requested, f"a Sobol design over {n_inputs} inputs needs at least "
                                            f"{8 * (n_inputs + 2)} shots")
    return base * (n_inputs + 2)


def sobol_problem(study: MonteCarloSpec) -> dict:
    """The SALib problem of the study's inputs: their names, distributions and bounds."""
    return {"num_vars": len(study.dists), "names": study.keys,
            "dists": [d.salib()[0] for d in study.dists], "bounds": [d.salib()[1] for d in study.dists]}


@functools.lru_cache(maxsize=4)
def sobol_matrix(study: MonteCarloSpec):
    """SALib's Sobol design for the study's inputs: (shots, K) and the SALib problem.
    Kept per study in a process: every batch takes its rows from it (drawing it costs as
    much as a few shots)."""
    try:
        from SALib.sample import sobol as sobol_sample
    except ImportError:
        raise RigError("--sobol needs SALib: pip install \".[sobol]\"") from None
    problem = sobol_problem(study)
    base = study.shots // (len(study.dists) + 2)
    X = sobol_sample.sample(problem, base, calc_second_order=False, seed=study.seed)
    if X.shape[0] != study.shots:
        raise RigError(f"a Sobol study needs base x (K + 2) shots; use {sobol_shots(study.shots, len(study.dists))}")
    return X, problem


def sobol_indices(study, X, Y) -> dict:
    """First-order and total Sobol indices (SALib) of one output for each input."""
    from SALib.analyze import sobol

    problem = sobol_problem(study)
    Y = np.asarray(Y, float)
    if not np.all(np.isfinite(Y)):
        Y = np.where(np.isfinite(Y), Y, np.nanmean(Y))
    s = sobol.analyze(problem, Y[: X.shape[0]], calc_second_order=False, seed=study.seed)
    names = problem["names"]
    def pick(key):
        return {n: float(v) for n, v in zip(names, s[key])}
    total = pick("ST")
    return {"first_order": pick("S1"), "first_order_conf95": pick("S1_conf"), "total": total,
            "total_conf95": pick("ST_conf"), "dominant": max(total, key=lambda name: total[name]),
            "base_samples": int(X.shape[0] // (len(names) + 2)),
            "note": "the instruments' own noise is not in the design and adds to every index; "
                    "indices are trustworthy where their 95% half-widths are small"}
