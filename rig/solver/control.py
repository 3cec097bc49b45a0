"""The accuracy contract: ``accuracy`` bounds the largest error of every recorded force,
relative to its dynamic peak, over the whole record (``solution.relative_error``), and the
solve that meets it is the cheapest the control finds, not one far more accurate than
asked: the delivered error is aimed at accuracy / 3, inside [accuracy / 10, accuracy].

A-posteriori estimate (every Solution carries one). A companion solve at half the step
records the same channels (no frames); the error of the solution at step h is

    e(h) = e(h) - e(h/2) + e(h/2) ~ max |F_h - F_h/2| R / (R - 1),   R = e(h) / e(h/2),

R = RICHARDSON. The companion measures the solution's own error: on the benchmark
problems and the published scenes the estimate is within a factor 1.25 of the true error
(log-sd; always within 1.6), where a companion at twice the step, half the price, misses
by more than a factor 3 one time in four. A struck chain's error is a power of the step
only on average (contacts that open and close make it irregular), and Richardson from a
coarser solve extrapolates that irregularity; docs/solver.md has the measurements.

Control. The first step comes from the a-priori rule (rig/solver/stepsize.py), set on the
easiest of the measured problems so that a first try is cheap. A solve whose estimate lies
outside [ACCEPT_LOW, ACCEPT_HIGH] x accuracy is done again at the step the estimates ask
for: the power law through the two nearest tries that bracket the target, else
h (accuracy / (3 e(h)))^(1/P_CONTROL); at most MAX_ATTEMPTS solves in all. Of the solves
done, the one returned is the cheapest whose estimate is in that band (else within the
accuracy, else the most accurate). A study calibrates its step once, from its nominal shot
(rig/study/nominal.py), and its shots reuse it without companions.

Bound. The control's work is bounded before it starts: its tries and their companions
together take at most WORK_BUDGET solves at its first step (in steps), so no try goes
finer than the budget left allows; and it stops where its finest try, at least 4 times
finer than its coarsest, brought the estimate down by less than NO_FALL (the error does
not fall with the step).
The measured scenes settle between 0.07 and 1.9 times the first step at 3 to 15 solves of
the final one (docs/solver.md); a dashpot chain held to 1e-6 needs 1/420 of it (about 1500
solves of the first step). A record whose error does not fall (a steel chain with PTFE's
bead mass: 0.57 at every step) had the control shrink the step 16 times per try, each try
16 times dearer, for minutes. Where the control stops above the accuracy, ``solve``
refuses (AccuracyNotReached, naming the accuracy, the duration, the estimate reached, the
steps tried and a way out), and a caller that bounds the step itself (a fit's pilot) takes the best try with
its estimate.

Fine records. A record asked on a grid finer than CONTROL_GRID_S (a scope sampling at
GS/s) is controlled on that grid: the tries and their companions record every
CONTROL_GRID_S, and the chosen try's step is integrated once more recording the asked grid
(the same steps, the same motion; its estimate is the control's). Ten tries on a grid of
millions of samples had cost ten times that one solve.

Way out. The most accurate try and its companion give the error of every shorter record
(``error_over_time``): where the error stays within the accuracy over the record's first
part and grows with time after, the refusal names the longest solver.duration that
reaches it (the steel chain above: within 1e-4 until 1.1 ms, 0.57 at 3 ms; 1.1 ms then
passes at 2.3e-5); where the tries reach a usable error (COARSEST_ACCURACY), the
solver.accuracy they reach.
"""
from __future__ import annotations

import math
import time
from dataclasses import replace

import numpy as np

from rig.errors import RigError
from rig.solver.ensemble import integrate_one
from rig.solver.methods import Method
from rig.solver.problem import ChainProblem
from rig.solver.run import Unstable, time_grid
from rig.solver.saveat import SaveAt
from rig.solver.solution import STATIC, Solution, Status, relative_error
from rig.solver.stepsize import COARSEST_ACCURACY, Stepping, default_step, largest_step

RICHARDSON = 10.0    # e(h) / e(h/2), order ~3.3: the median over the measured problems (docs/solver.md)
P_CONTROL = 3.0      # the order the control assumes when it moves the step
TARGET = 1.0 / 3.0   # aimed-at error, as a fraction of the accuracy setting
ACCEPT_LOW, ACCEPT_HIGH = 0.2, 0.5  # estimates in this band (x accuracy) end the control
MAX_ATTEMPTS = 5
COMPANION = 2        # the companion takes this many steps for each of the solution's
WORK_BUDGET = 2048.0  # the control's steps, companions included, in solves at its first step
NO_FALL = 2.0        # a step 4+ times finer whose estimate fell by less than this: the error does not fall
CONTROL_GRID_S = 1e-7  # the control records no finer than this (s); a finer grid is recorded by the chosen step once


class AccuracyNotReached(RigError):
    """The accuracy control's work budget ran out with its estimate above the accuracy."""


def companion_estimate(problem: ChainProblem, t_end: float, save: SaveAt, m: Method, stepping: Stepping,
                       sol: Solution) -> tuple:
    """(estimate, basis) of the error of ``sol`` (solved with ``stepping``): a companion
    solve of the same channels (no frames) at half its step (and half the head's substep),
    e(h) = max |F_h - F_h/2| R / (R - 1). (None, why) where no estimate can be had."""
    comp, basis = companion_solve(problem, t_end, save, m, stepping, sol)
    return (None if comp is None else relative_error(sol.forces, comp.forces) * RICHARDSON / (RICHARDSON - 1.0),
            basis)


def companion_solve(problem: ChainProblem, t_end: float, save: SaveAt, m: Method, stepping: Stepping,
                    sol: Solution) -> tuple:
    """(the companion Solution at half ``sol``'s step, basis), or (None, why there is none)."""
    if not save.names:
        return None, "nothing recorded"
    companion = Stepping(sol.stats.dt_s / COMPANION, stepping.head, stepping.inner_dt / COMPANION)
    comp = integrate_one(problem, t_end, SaveAt(save.probes, save.sample_interval), m, companion)
    return (comp, "companion at dt/2") if comp.success else (None, "the companion at dt/2 was unstable")


def error_over_time(forces: dict, reference: dict) -> np.ndarray:
    """Element j: ``relative_error`` of the records cut after their sample j (the error a
    solve of that shorter duration would show, each channel against its dynamic peak so
    far; before any channel moves by more than STATIC of its force, against STATIC x that
    force)."""
    size = min((r.size for r in reference.values()), default=0)
    if size == 0:
        return np.zeros(0)
    gaps = {k: np.maximum.accumulate(np.abs(forces[k][:size] - r[:size])) for k, r in reference.items()}
    peaks = {k: np.maximum.accumulate(np.abs(r[:size] - r[0])) for k, r in reference.items()}
    top = np.max(np.stack(list(peaks.values())), axis=0)
    static = STATIC * np.max(np.stack([np.maximum.accumulate(np.abs(r[:size])) for r in reference.values()]), axis=0)
    still = top <= static  # no pulse yet: the differences are rounding, measured against STATIC x the force
    floor = np.maximum(np.where(still, static, 1e-6 * top), np.finfo(float).tiny)
    return np.max(np.stack([gaps[k] / np.maximum(np.where(still, static, peaks[k]), floor) for k in gaps]), axis=0)


def with_estimate(sol: Solution, estimate, basis: str, attempts: int, cpu_s: float) -> Solution:
    """The solution with its estimate and the control's figures in its stats."""
    return replace(sol, stats=replace(sol.stats, error_estimate=estimate, estimate_basis=basis,
                                      attempts=attempts, cpu_s=cpu_s))


def estimated_solve(problem: ChainProblem, t_end: float, save: SaveAt, m: Method, stepping: Stepping,
                    estimate: bool = True) -> Solution:
    """One solve at ``stepping``, with its companion estimate unless ``estimate`` is False."""
    t0 = time.process_time()
    sol = Unstable.check(integrate_one(problem, t_end, save, m, stepping), stepping)
    est, basis = companion_estimate(problem, t_end, save, m, stepping, sol) if estimate else (None, "not asked")
    return with_estimate(sol, est, basis, 1, time.process_time() - t0)


def controlled_solve(problem: ChainProblem, t_end: float, save: SaveAt, m: Method, accuracy: float,
                     shortest: float = 0.0, strict: bool = True) -> Solution:
    """The solve meeting ``accuracy`` (module doc): tries at most MAX_ATTEMPTS steps, none
    shorter than ``shortest`` (s; a caller's bound on the cost) and all of them, companions
    included, within WORK_BUDGET solves at the first step. Where the bound ends the control
    above the accuracy: AccuracyNotReached if ``strict``, else the most accurate try,
    its estimate above the accuracy, with status ACCURACY_NOT_REACHED (its message says why)."""
    t0 = time.process_time()
    asked, save = save, (replace(save, sample_interval=CONTROL_GRID_S) if save.sample_interval < CONTROL_GRID_S
                         else save)
    first = default_step(problem, m, accuracy, t_end)
    longest = largest_step(problem, m, t_end)
    dt = max(min(first.dt, longest), shortest)
    budget = WORK_BUDGET * time_grid(t_end, dt, t_end)[0]  # steps
    spent = 0
    stop = f"{MAX_ATTEMPTS} tries"  # what ended the control, should it end above the accuracy
    tried = []  # (solution, estimate, basis)
    steppings = {}  # id(solution) -> its Stepping
    for _ in range(MAX_ATTEMPTS):
        stepping = Stepping(dt, first.head, first.inner_dt * dt / first.dt)
        sol = integrate_one(problem, t_end, save, m, stepping, accuracy)
        steppings[id(sol)] = stepping
        if not sol.success:
            spent += time_grid(t_end, dt, t_end)[0]
            dt *= 0.5
            continue
        comp, basis = companion_solve(problem, t_end, save, m, stepping, sol)
        est = None if comp is None else relative_error(sol.forces, comp.forces) * RICHARDSON / (RICHARDSON - 1.0)
        spent += sol.stats.steps * (1 + COMPANION)
        tried.append((sol, est, basis, comp))
        if est is None or ACCEPT_LOW * accuracy <= est <= ACCEPT_HIGH * accuracy:
            break
        if est < ACCEPT_LOW * accuracy and dt >= longest:
            break  # as coarse as the chain allows
        affordable = t_end * (1 + COMPANION) / (budget - spent) if budget > spent else math.inf
        finer = max(min(_next_step(tried, TARGET * accuracy), longest), shortest, affordable)
        if est > ACCEPT_HIGH * accuracy and not _falls(tried):
            coarsest = max(t[0].stats.dt_s for t in tried)
            stop = (f"a step {coarsest / dt:.3g} times finer, which lowered it by less than {NO_FALL:g} times "
                    f"(the error does not fall with the step)")
            break
        if est > ACCEPT_HIGH * accuracy and finer >= dt:
            stop = ("its step floor" if finer == shortest else
                    f"its work budget ({WORK_BUDGET:g} solves at its first step)")
            break
        dt = finer
    if not tried:
        raise Unstable(f"unstable at every step tried down to dt = {2 * dt:.4g} s", stepping)
    sol, est, basis, _ = _choice(tried, accuracy)
    if asked is not save:  # the chosen step, recording the asked grid
        sol = Unstable.check(integrate_one(problem, t_end, asked, m, steppings[id(sol)], accuracy),
                             steppings[id(sol)])
    if est is not None and est > accuracy:
        why = _not_reached(tried, accuracy, first.dt, stop, t_end)
        if strict:
            raise AccuracyNotReached(why)
        sol = replace(sol, status=Status.ACCURACY_NOT_REACHED, detail=f" ({why})")
    return with_estimate(sol, est, basis, len(tried), time.process_time() - t0)


def _not_reached(tried: list, accuracy: float, first: float, stop: str, t_end: float) -> str:
    """One line: the accuracy, the best estimate reached, the steps tried, what stopped the
    control, and the way out: where the most accurate try's error stays within the accuracy
    over the record's first part and grows later (a long record of a stiff chain: after the
    pulse's reflections its motion departs exponentially from any nearby one, so the error
    grows tenfold every so often whatever the step), the duration that reaches it; and the
    accuracy the tries reach."""
    sol, best, _, comp = min((t for t in tried if t[1] is not None), key=lambda t: t[1])
    steps = sorted(t[0].stats.dt_s for t in tried)
    ways = [f"a solver.accuracy of at least {best:.2g}"] if best <= COARSEST_ACCURACY else []
    reach = reached_until(sol, comp, accuracy)
    if reach is not None:
        within, tenfold = reach
        growth = (f", tenfold every {tenfold:.2g} s: the motion departs from any nearby one as the record goes on"
                  if tenfold else "")
        ways.insert(0, f"a solver.duration of at most {within:.2g} s (the error stays within the accuracy until "
                       f"then and grows with time{growth})")
    way_out = ": " + " or ".join(ways) if ways else ": check the scene's values"
    return (f"accuracy = {accuracy:g}: not reached; over solver.duration = {t_end:.3g} s the error estimate "
            f"stayed at {best:.2g} or more over {len(tried)} tries from dt = {steps[-1]:.3g} s down to "
            f"{steps[0]:.3g} s ({steps[0] / first:.2g} of the first step) and the accuracy control stopped at "
            f"{stop}{way_out}")


def reached_until(sol: Solution, comp, accuracy: float) -> tuple | None:
    """(the longest record, s from the impact, whose error estimate, ``sol`` against its
    companion ``comp``, is within ``accuracy``; the time its error took to grow tenfold on
    its way there, from accuracy / 100, or None where it did not rise that way). None where
    there is no companion or only a record shorter than a tenth of this one is within the
    accuracy (a shorter record is then no way out)."""
    if comp is None:
        return None
    err = error_over_time(sol.forces, comp.forces) * RICHARDSON / (RICHARDSON - 1.0)
    within = np.flatnonzero(err <= accuracy)  # the last: the longest record within it
    if within.size == 0 or within[-1] < err.size // 10:
        return None
    end = within[-1]
    low = np.flatnonzero(err[:end] <= accuracy / 100)
    tenfold = (end - low[-1]) * sol.sample_interval / 2 if low.size and low[-1] < end else None
    return float(end * sol.sample_interval), tenfold


def _falls(tried: list) -> bool:
    """Whether the error falls with the step over the tries: False where the finest try (at
    least 4 times finer than the coarsest) brought the estimate down by less than NO_FALL
    (a method of order 3 would have taken 64 or more). Coarsest against finest, not the
    last two: a record whose error lingers on a plateau over a few steps before it falls
    again (a contact that closes or not by a hair, docs/solver.md) is not stopped by it."""
    known = [(t[0].stats.dt_s, t[1]) for t in tried if t[1] is not None]
    if len(known) < 2:
        return True
    (a, ea), (b, eb) = max(known), min(known)
    return not (b <= a / 4 and eb * NO_FALL > ea)


def _next_step(tried: list, target: float) -> float:
    """The step whose error should be ``target``: between the two nearest tries that
    bracket it, the power law through them (log-log secant); else from the last try with
    the order P_CONTROL, at most 16 times finer or coarser."""
    points = sorted((t[0].stats.dt_s, t[1]) for t in tried if t[1])
    below = [pt for pt in points if pt[1] < target]
    above = [pt for pt in points if pt[1] > target]
    if below and above:
        (h0, e0), (h1, e1) = max(below), min(above)
        if h1 > h0 and e1 > e0:
            order = math.log(e1 / e0) / math.log(h1 / h0)
            return h0 * (target / e0) ** (1.0 / order)
    h, e = tried[-1][0].stats.dt_s, tried[-1][1]
    factor = (target / e) ** (1.0 / P_CONTROL) if e > 0 else 16.0
    return h * min(max(factor, 1.0 / 16.0), 16.0)


def _choice(tried: list, accuracy: float) -> tuple:
    """Of the solves done: the cheapest whose estimate is in the accepted band, else the
    cheapest within the accuracy, else the most accurate."""
    def cheapest(group):
        return min(group, key=lambda t: t[0].stats.steps)

    band = [t for t in tried if t[1] is not None and ACCEPT_LOW * accuracy <= t[1] <= ACCEPT_HIGH * accuracy]
    within = [t for t in tried if t[1] is not None and t[1] <= accuracy]
    if band or within:
        return cheapest(band or within)
    return min(tried, key=lambda t: math.inf if t[1] is None else t[1])
