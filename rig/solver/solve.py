"""solve(problem, t_end, save, method, accuracy | dt) -> Solution."""
from __future__ import annotations

import math

import numpy as np

from rig.errors import RigError, invalid
from rig.model.chain import Chain
from rig.solver.control import controlled_solve, estimated_solve
from rig.solver.methods import DEFAULT_METHOD
from rig.solver.methods import method as get_method
from rig.solver.problem import ChainProblem
from rig.solver.saveat import SaveAt
from rig.solver.solution import Solution
from rig.solver.stepsize import Stepping, checked_accuracy, stability_limit
from rig.units import is_real


def problem_of(chain_or_problem) -> ChainProblem:
    """The ChainProblem of a Chain (or the problem itself)."""
    if isinstance(chain_or_problem, ChainProblem):
        return chain_or_problem
    if isinstance(chain_or_problem, Chain):
        return ChainProblem.from_chain(chain_or_problem)
    raise invalid("problem", type(chain_or_problem).__name__, "a Chain or a ChainProblem")


def solve(problem: ChainProblem | Chain, t_end: float, *, save: SaveAt | None = None,
          method: str = DEFAULT_METHOD, accuracy: float | None = None,
          dt: float | Stepping | None = None, estimate: bool = True) -> Solution:
    """Integrate ``problem`` (a ChainProblem, or a Chain) from the impact (t = 0) to
    ``t_end`` (s), recording what ``save`` names (default: nothing but the final state).

    ``accuracy`` (default 1e-4): the largest error of every recorded force, relative to
    its dynamic peak, over the whole record; the step is found by the accuracy control
    (rig/solver/control.py), which aims at accuracy / 3. ``dt`` (s, single rate; or a
    Stepping, possibly multirate) fixes the step instead; a dt beyond the method's
    stability limit for this chain is refused. Either way the solution carries an
    a-posteriori error estimate (``stats.error_estimate``), from a companion solve at half
    the step, unless ``estimate`` is False (with dt only).
    """
    m = get_method(method)
    problem = problem_of(problem)
    save = SaveAt() if save is None else save
    if not isinstance(save, SaveAt):
        raise invalid("save", type(save).__name__, "a SaveAt: SaveAt({name: probe}, sample_interval=...)")
    if not is_real(t_end) or not math.isfinite(t_end) or t_end <= 0:
        raise invalid("t_end", t_end, "end time must be a finite number > 0 s")
    t_end = float(t_end)
    if dt is None:
        if not estimate:
            raise invalid("estimate", estimate, "the accuracy control needs the estimate; give dt to skip it")
        _check_head(problem, 0)
        return controlled_solve(problem, t_end, save, m, checked_accuracy(accuracy))
    if accuracy is not None:
        raise invalid("dt", dt, "give either dt or accuracy, not both")
    stepping = dt if isinstance(dt, Stepping) else Stepping(float(dt) if is_real(dt) else dt)
    if not (is_real(stepping.dt) and math.isfinite(stepping.dt) and stepping.dt > 0):
        raise invalid("dt", dt, "time step must be a finite number > 0 s")
    limit = stability_limit(problem, m, stepping.head)
    if stepping.dt > limit:
        raise RigError(
            f"dt = {stepping.dt:.4g} s is beyond the stability limit of {m.name} for this chain "
            f"(about {limit:.4g} s at the estimated peak forces); use dt <= {limit:.3g} s "
            f"or leave dt unset to choose it from the accuracy target")
    _check_head(problem, stepping.head)
    return estimated_solve(problem, t_end, save, m, stepping, estimate)


def _check_head(problem: ChainProblem, head: int):
    p = problem
    hertz = (p.expo[1:head + 1] == 1.5) & (p.damping[1:head + 1] == 0.0) & (p.dashpot[1:head + 1] == 0.0)
    if head and (not np.all(hertz) or head >= p.n_bodies - 2):
        raise invalid("dt.head", head, "a multirate head takes elastic Hertz contacts of a chain longer than the head")
