"""Identifiability on virtual shots: can a fit to Fig. 3's observations (rig.study.fig3) find
a contact parameter again, with honest uncertainties?

For one parameter (a scene key with bounds), a truth inside them and the other keys fixed
(overrides), N virtual data sets are drawn: each observation's figure on the model's shots at
the truth (noise-free, rig.fit.observations) plus Gaussian noise of the observation's sd, from
a numpy Generator seeded with ``seed`` (the same seed gives the same data sets and fits). The
parameter is fitted to each set (rig.fit.fitting.fit of an ObservationObjective, the
observations' values replaced in memory), starting at the truth: the question is the interval,
not the optimiser's reach. A 95% interval holds the truth where the fit converged with a
finite sd and ci95 contains it; for a sound fit about 19 of 20 do.

Cost: one parameter per fit, the others fixed at the truth; every fit of a parameter shares
the pilot (the solver's step, calibrated once at the truth, rig.fit.evaluate).
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, replace

import numpy as np

from rig.errors import RigError, invalid
from rig.fit.fitting import fit
from rig.fit.observations.objective import ObservationObjective
from rig.fit.parameters import FitParameter, parse_parameter
from rig.study import fig3
from rig.units import check_digits, number, quantity

DRAWS = 20
"""Virtual data sets per parameter."""


@dataclass(frozen=True)
class Question:
    """One parameter to find again: ``bounds`` (``KEY=LO:HI`` as rig fit's --param), its
    ``truth`` (a quantity in the key's unit, or a plain number) and the other keys fixed
    (``overrides``, KEY=VALUE texts); ``why``: where the truth comes from."""

    bounds: str
    truth: str
    overrides: tuple
    why: str


RATE_REFERENCE = "chain.yield_reference_rate=0.1 m/s"
"""The reference closing rate of the rate exponent's question: the yield rises only above it,
and few contacts of the chain close faster than the 1 m/s default (the striker comes at
0.89 m/s), which would leave the exponent unseen."""
DASHPOT = ("chain.youngs_modulus=0.84 GPa", "chain.contact_law=powerlaw-dashpot")

QUESTIONS = (
    Question("chain.yield_force=0.3 N:2 N", "0.8 N", fig3.PARAMETER_SET,
             "the Fig. 3 parameter set's yield force"),
    Question("chain.yield_rate_exponent=0:0.5", "0.1", fig3.PARAMETER_SET + (RATE_REFERENCE,),
             "a modest rate dependence (PTFE's yield rises some 10-20% a decade of strain rate), at the "
             "Fig. 3 set with the yield referred to 0.1 m/s"),
    Question("chain.static_yield_ratio=0.2:1", "0.6", fig3.PARAMETER_SET,
             "the Fig. 3 parameter set's static yield ratio"),
    Question("chain.dashpot_gamma=0.005:0.5", "0.05", DASHPOT + ("chain.dashpot_exponent=1",),
             "the Fig. 3 set's dashpot, 0.05 kg/s, as a power-law dashpot of exponent 1 (fixed), the "
             "elastic law Hertz's at 0.84 GPa"),
    Question("chain.dashpot_exponent=0.5:2", "1.2", DASHPOT + ("chain.dashpot_gamma=0.05",),
             "a slightly super-linear dashpot of gamma 0.05 (fixed) beside Hertz's law at 0.84 GPa"),
)
"""The new contact parameters' questions, truths near fig3.PARAMETER_SET."""


@dataclass(frozen=True)
class Coverage:
    """A parameter's identifiability (module doc): ``truth``, bounds ``lo``..``hi`` (SI,
    ``unit``), the fixed ``overrides``, the ``seed``, and per data set the fit's ``estimates``,
    ``stds``, whether it ``converged``, its 95% interval (``intervals``: (lo, hi), cut at the
    bounds, rig.fit.fitting) and whether that ``holds`` the truth;
    ``wall_s``: seconds it took. ``refused``: why no data set could be fitted (the fit's own
    refusal, e.g. a parameter the observations do not see: rig.fit.checks.unseen), with no
    estimates; "" where they were."""

    key: str
    unit: str
    truth: float
    lo: float
    hi: float
    overrides: tuple
    seed: int
    estimates: tuple
    stds: tuple
    converged: tuple
    holds: tuple
    intervals: tuple
    wall_s: float
    refused: str = ""

    @property
    def n(self) -> int:
        return len(self.estimates)

    @property
    def count(self) -> int:
        """How many 95% intervals hold the truth."""
        return sum(self.holds)

    def as_dict(self) -> dict:
        finite = [s for s in self.stds if math.isfinite(s)]
        widths = [(hi - lo) / (self.hi - self.lo) for lo, hi in self.intervals]
        return {"key": self.key, "unit": self.unit, "truth": self.truth, "bounds": [self.lo, self.hi],
                "overrides": list(self.overrides), "seed": self.seed, "n": self.n, "holding": self.count,
                "converged": sum(self.converged), "estimates": list(self.estimates),
                "stds": [s if math.isfinite(s) else None for s in self.stds],
                "mean_estimate": float(np.mean(self.estimates)) if self.n else None,
                "median_std": float(np.median(finite)) if finite else None,
                "median_width_over_span": float(np.median(widths)) if self.n else None,
                "estimate_spread": float(np.std(self.estimates, ddof=1)) if self.n > 1 else None,
                "holds": list(self.holds), "intervals": [list(i) for i in self.intervals], "wall_s": self.wall_s,
                "refused": self.refused or None}


def truth_value(param: FitParameter, text: str) -> float:
    """``text`` (a quantity in the key's unit, or a plain number for a pure one) in SI,
    strictly inside the bounds; RigError naming the key otherwise."""
    field = f"{param.key} truth"
    check_digits(text, field)
    value = number(text, field, "a finite number") if param.unit == "1" else quantity(text, param.unit, field)
    if not param.lo < value < param.hi:
        raise invalid(field, text, f"inside its bounds, {param.shown(param.lo)} < truth < {param.shown(param.hi)}")
    return value


def coverage(param: FitParameter, truth: float, overrides=(), observations=None, n: int = DRAWS, seed: int = 0,
             progress=None) -> Coverage:
    """The identifiability of ``param`` at ``truth`` (SI) over ``n`` virtual data sets of
    ``observations`` (Observations; default the Fig. 3 set), the other keys ``overrides``."""
    if not param.lo < truth < param.hi:
        raise invalid(f"{param.key} truth", truth,
                      f"inside its bounds, {param.shown(param.lo)} < truth < {param.shown(param.hi)}")
    if n < 1:
        raise invalid("draws", n, "a whole number >= 1")
    observations = tuple(observations or fig3.observations())
    overrides = tuple(overrides) + (param.override(truth),)
    tell = progress or (lambda text: None)
    start = time.perf_counter()
    scene = observations[0].shot.scene
    at_truth = ObservationObjective(scene, (param,), observations, overrides)
    figures = at_truth.evaluate([np.array([truth])])[0]
    missing = [o.label for o, f in zip(observations, figures) if not math.isfinite(f)]
    if missing:
        raise RigError(f"{param.key} truth = {param.shown(truth)}: the model gives no figure for {missing[0]}; "
                       "choose a truth whose shots have it")
    sd = np.array([o.sd for o in observations])
    rng = np.random.default_rng(seed)
    rows = []
    for i in range(n):
        data = figures + sd * rng.standard_normal(sd.size)
        drawn = tuple(replace(o, value=float(y)) for o, y in zip(observations, data))
        objective = ObservationObjective(scene, (param,), drawn, overrides)
        objective.pilot = at_truth.pilot  # the same shots' numerics: calibrated once
        try:
            result = fit(objective)
        except RigError as exc:  # the fit refuses the question itself (a parameter the data do not see)
            tell(f"{param.key}: not fitted: {exc}")
            return Coverage(param.key, param.unit, truth, param.lo, param.hi, overrides[:-1], seed, (), (), (), (), (),
                            time.perf_counter() - start, str(exc))
        est, std = float(result.estimate[0]), float(result.std[0])
        lo, hi = (float(x) for x in result.ci95[0])
        ok = bool(result.converged and math.isfinite(std))
        rows.append((est, std, ok, ok and lo <= truth <= hi, (lo, hi)))
        tell(f"{param.key}: fit {i + 1}/{n}: {param.shown(est)} +- {param.shown(std)} "
             f"({sum(r[3] for r in rows)}/{i + 1} intervals hold the truth)")
    estimates, stds, converged, holds, intervals = (tuple(col) for col in zip(*rows))
    return Coverage(param.key, param.unit, truth, param.lo, param.hi, overrides[:-1], seed, estimates, stds, converged,
                    holds, intervals, time.perf_counter() - start)


def question_coverage(question: Question, n: int = DRAWS, seed: int = 0, progress=None) -> Coverage:
    """``coverage`` of one Question on the Fig. 3 observations."""
    param = parse_parameter(question.bounds)
    return coverage(param, truth_value(param, question.truth), question.overrides, None, n, seed, progress)


def study(questions=QUESTIONS, n: int = DRAWS, seed: int = 0, progress=None) -> dict:
    """Every question's coverage: {"seed", "draws", "parameters": [Coverage.as_dict() with
    its question's "why"], "wall_s"}."""
    start = time.perf_counter()
    rows = []
    for q in questions:
        rows.append(dict(question_coverage(q, n, seed, progress).as_dict(), why=q.why))
    return {"seed": seed, "draws": n, "observations": "Fig. 3 of Daraio et al. 2006 (rig.study.fig3)",
            "parameters": rows, "wall_s": time.perf_counter() - start}


def table(result: dict) -> str:
    """identifiability.md: one row per parameter."""
    lines = [(f"# Identifiability on virtual shots (Fig. 3 observations, {result['draws']} data sets each, "
              f"seed {result['seed']})"), "",
             ("| parameter | truth | bounds | 95% intervals holding the truth | converged | mean estimate "
              "| spread of estimates | median sd | median 95% width / bounds' span | wall |"),
             "|---|---|---|---|---|---|---|---|---|---|"]
    for r in result["parameters"]:
        u = "" if r["unit"] == "1" else " " + r["unit"]
        if r["refused"]:
            lines.append(f"| {r['key']} | {r['truth']:.4g}{u} | {r['bounds'][0]:.4g}..{r['bounds'][1]:.4g}{u} "
                         f"| not fitted: {r['refused']} | | | | | | {r['wall_s']:.0f} s |")
            continue
        sd = "n/a" if r["median_std"] is None else f"{r['median_std']:.3g}"
        spread = "n/a" if r["estimate_spread"] is None else f"{r['estimate_spread']:.3g}"
        lines.append(f"| {r['key']} | {r['truth']:.4g}{u} | {r['bounds'][0]:.4g}..{r['bounds'][1]:.4g}{u} "
                     f"| {r['holding']}/{r['n']} | {r['converged']}/{r['n']} | {r['mean_estimate']:.4g} "
                     f"| {spread} | {sd} | {r['median_width_over_span']:.2f} | {r['wall_s']:.0f} s |")
    lines += ["", "Truths and fixed keys:", ""]
    lines += [f"- {r['key']}: {r['why']}; fixed: {', '.join(r['overrides'])}" for r in result["parameters"]]
    lines += ["", f"Total wall time {result['wall_s']:.0f} s."]
    return "\n".join(lines) + "\n"
