"""What a fit refuses, and what it flags, so that it never reports what the data cannot
say with full confidence.

Refused (RigError, one line) before any solve: a bound the scene or the solver cannot take
(a modulus of 1e300 Pa has no contact time scale), fewer data than fitted parameters, the
same data twice (it would narrow the intervals by sqrt(2) without a new measurement). At
the first Jacobian: a parameter that moves the residuals by less than one standard
deviation across its whole bounds (the data do not see it; an exactly zero column gave an
sd of 0 from the pseudo-inverse). Flagged at the result: chi2/dof far above 1 (p below
IMPLAUSIBLE_P: the intervals are widened by sqrt(chi2/dof), and the fit is not plausible),
a 95% interval past both bounds (undetermined), a value at a bound. A flagged fit writes no
fitted scene (``unusable``).
"""
from __future__ import annotations

import hashlib
import math
from pathlib import Path

import numpy as np

from rig.errors import RigError, invalid
from rig.experiment.shot import Rig
from rig.solver.methods import method as get_method
from rig.solver.problem import ChainProblem
from rig.solver.stepsize import checked_accuracy, default_step

IMPLAUSIBLE_P = 1e-3
"""A fit whose chi2 has a p-value below this: the model does not describe the data."""


def check_bounds(scene: str, overrides: list, params: tuple, start) -> None:
    """Refuse, naming the key, the bound and why, a bound at which the scene refuses its
    shot or the solver cannot choose a step (each bound tried with the other parameters at
    their ``start`` values)."""
    for k, p in enumerate(params):
        others = [q.override(x) for j, (q, x) in enumerate(zip(params, start)) if j != k]
        for name, value in (("LO", p.lo), ("HI", p.hi)):
            field = f"--param {p.key} {name}"
            try:
                with np.errstate(all="raise"):
                    rig = Rig.from_scene(scene, list(overrides) + others + [p.override(value)])
                    problem, s = ChainProblem.from_chain(rig.chain), rig.solver
                    dt = default_step(problem, get_method(s.method), checked_accuracy(s.accuracy), s.duration).dt
            except RigError as exc:
                raise invalid(field, p.shown(value), f"the scene refuses it ({exc})") from None
            except (ArithmeticError, FloatingPointError) as exc:
                dt, why = math.nan, type(exc).__name__
            else:
                why = f"step {dt:.3g} s"
            if not (math.isfinite(dt) and dt > 0):
                raise invalid(field, p.shown(value), f"outside what the solver can take: no time step for its "
                                                     f"shot ({why}); narrow the bounds to physical values")


def at_values(params: tuple, theta) -> str:
    """'KEY = value unit, ...' of a candidate, for a message."""
    return ", ".join(f"{p.key} = {p.shown(v)}" for p, v in zip(params, theta))


def check_data_count(n_data: int, n_params: int, n_nuisance: int, what: str) -> None:
    """Refuse a fit of more parameters than data (before any solve)."""
    if n_data < n_params + n_nuisance:
        nuisance = f" and {n_nuisance} of the instruments (gains, delays, trigger)" if n_nuisance else ""
        raise RigError(f"{what}: {n_data} data for {n_params} --param keys{nuisance}; a fit needs at least "
                       f"as many data as parameters")


def check_distinct_files(field: str, paths) -> None:
    """Refuse the same file (or the same bytes under another name) given twice."""
    seen: dict[str, str] = {}
    for path in paths:
        try:
            digest = hashlib.sha256(Path(path).read_bytes()).hexdigest()
        except OSError:
            continue  # the reader names a file it cannot read
        if digest in seen:
            raise invalid(field, str(path), f"the same data as {seen[digest]}: a record counted twice would "
                                            "narrow the intervals without a new measurement; give each file once")
        seen[digest] = str(path)


def check_distinct_channels(channels: list) -> None:
    """Refuse two fitted channels with the same samples (the same shot twice in an archive)."""
    seen: dict[str, str] = {}
    for c in channels:
        digest = hashlib.sha256(c.t.tobytes() + c.y.tobytes()).hexdigest()
        if digest in seen:
            raise invalid("records", f"record {c.record + 1} {c.name}", f"the same samples as {seen[digest]}: "
                          "a record counted twice would narrow the intervals; give each shot once")
        seen[digest] = f"record {c.record + 1} {c.name}"


def unseen(params: tuple, J: np.ndarray) -> None:
    """Refuse a fit of a scene parameter the data cannot see: its Jacobian column (J in
    units of each parameter's bound span) has a norm below 1, i.e. moving it across its
    whole bounds moves the residuals by less than one standard deviation in all, and its sd
    would be wider than its bounds (or 0 from the pseudo-inverse, for an exactly zero
    column: e.g. striker.velocity against points that set the velocity themselves)."""
    for k, p in enumerate(params):
        size = float(np.linalg.norm(J[:, k]))
        if not size >= 1.0:
            raise invalid("--param", p.key, f"the data do not see it: moving it across its whole bounds moves the "
                                            f"residuals by {size:.2g} standard deviations in all (less than 1), "
                                            "so its value cannot be fitted; leave it out")


def _misfit(result) -> str:
    return f"the model does not describe the data (chi2/dof {result.chi2_reduced:.3g}, p = {result.p_value:.2g})"


def unusable(result) -> str:
    """Why a converged fit does not stand for the scene ('' where it does): rig fit then
    writes no fitted scene and exits 1."""
    why = []
    if result.plausible is False:
        why.append(_misfit(result))
    if result.undetermined:
        why.append(f"the data do not determine {', '.join(result.undetermined)}")
    if result.at_bound:
        why.append(f"{', '.join(result.at_bound)} ended at a bound of --param (the best value may lie beyond it): "
                   f"widen the bounds")
    return "; ".join(why)


def result_warnings(result, params: tuple) -> list:
    """The lines that qualify a finished fit: no degrees of freedom, a chi2 that rules the
    model out, a parameter the data do not determine, a parameter at a bound."""
    out = []
    if result.dof == 0:
        out.append("as many data as parameters: chi2/dof and p are undefined, and the intervals rest on "
                   "the data's stated uncertainties alone")
    elif result.plausible is False:
        out.append(f"{_misfit(result)}: the fit is not plausible; its intervals, widened by "
                   f"sqrt(chi2/dof) = {result.interval_scale:.3g}, treat a systematic misfit as noise")
    for p, sd in zip(params, result.std):
        if p.key in result.undetermined:
            unit = "" if p.unit == "1" else f" {p.unit}"
            out.append(f"the data do not determine {p.key}: its sd {sd:.2g}{unit} puts its 95% interval past "
                       f"both of its bounds ({p.shown(p.lo)}, {p.shown(p.hi)})")
    for p, e in zip(params, result.estimate):
        if p.key in result.at_bound:
            side, bound = ("lower", p.lo) if abs(e - p.lo) <= abs(e - p.hi) else ("upper", p.hi)
            out.append(f"{p.key} = {p.shown(e)} is at its {side} bound {p.shown(bound)}: the best value may "
                       f"lie beyond it, and its interval is cut there")
    return out


def archived_setups(archive: str, scene: str, overrides: list, fitted: set, entries: list) -> list:
    """Each archived shot's set-up as the traces' fit models it: a virtual shot's own
    overrides (a sweep's striker velocity, say; the fitted keys are the fit's), an imported
    real record's none (it carries no settings: the scene and --set describe it). Refused in
    one line where a virtual shot is of another scene, or was fired with a setting its
    overrides on this scene and --set do not give (its scene text edited since, say): the
    model would not be the shot's."""
    out, models = [], {}
    for e in entries:
        if not e.simulated:
            out.append(())
            continue
        own = tuple(e.settings.get("overrides", ()))
        if own not in models:
            models[own] = dict(_flat(Rig.from_scene(scene, list(overrides) + list(own)).values))
        want = models[own]
        have = dict(_flat({k: v for k, v in e.settings.items() if k != "overrides"}))
        differ = sorted(k for k in set(want) | set(have) if k not in fitted and not k.startswith("solver.")
                        and not _same(want.get(k), have.get(k)))  # the solver's settings: the fit's own numerics
        if differ:
            k = differ[0]
            raise invalid("--archive", archive, f"shot {e.shot_id} was fired with {k} = {have.get(k)!r} where the "
                                                f"fit's model of it has {want.get(k)!r}"
                                                f"{f' (and {len(differ) - 1} more keys)' if len(differ) > 1 else ''}"
                                                f": give the scene it was fired from, and --set only keys it shares")
        out.append(own)
    return out


def _flat(node, prefix: str = ""):
    """(dotted key, value) of a nested settings dict."""
    for k, v in node.items():
        if isinstance(v, dict):
            yield from _flat(v, f"{prefix}{k}.")
        else:
            yield f"{prefix}{k}", v


def _same(a, b) -> bool:
    """Two settings' values alike (numbers to a relative 1e-12: an archive's JSON round trip)."""
    if isinstance(a, (int, float)) and isinstance(b, (int, float)) and not isinstance(a, bool):
        return math.isclose(float(a), float(b), rel_tol=1e-12, abs_tol=0.0)
    if isinstance(a, (list, tuple)) and isinstance(b, (list, tuple)):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b))
    return a == b
