"""How each Fig. 3 figure moves with each parameter, and where the parameters meet Fig. 3.

At a parameter set (scene overrides of both shots, rig.study.fig3.PARAMETER_SET unless given):

- each target figure's logarithmic sensitivity d ln(figure) / d ln(p) to each numeric key p
  the set gives (> 0), by central differences in ln p: p e^(+-STEP) (one-sided where a step
  would leave the key's allowed range), every candidate's shots solved in one batch
  (rig.fit.evaluate); a count of pulses is a step function: its sensitivity is 0 unless a
  step crosses a jump;
- each key's window: the contiguous range around its value, the other keys fixed, in which
  every target holds (rig.study.fig3.TARGETS): a scan of SCAN_POINTS values evenly in ln p
  from p / SCAN_FACTOR to p x SCAN_FACTOR (cut at the key's allowed range), then bisection in
  ln p of each edge to RESOLUTION; an edge the scan does not reach is reported open.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rig.errors import invalid
from rig.experiment import scene as scene_io
from rig.experiment.scene import key_spec
from rig.fit.observations.objective import ObservationObjective
from rig.fit.parameters import FitParameter
from rig.fit.points import scene_value
from rig.model.laws import PARAMETERS
from rig.study import fig3

STEP = 0.05
"""The central difference's step in ln p: p e^(+-0.05), +-5%."""
SCAN_FACTOR = 3.0
SCAN_POINTS = 9
RESOLUTION = 0.01
"""A window's edge is bisected until its passing and failing values differ by this in ln p
(1%); the edge reported is the passing one."""


@dataclass(frozen=True)
class Edge:
    """One side of a window: ``value`` (SI, the last value where every target holds), ``open``
    (the scan's end still holds: the window reaches further) and the targets that fail just
    past it (``failing``, empty where open)."""

    value: float
    open: bool
    failing: tuple


def window(holds, centre: float, lo: float, hi: float, points: int = SCAN_POINTS,
           resolution: float = RESOLUTION):
    """The contiguous range around ``centre`` (> 0) in which ``holds`` is true, looked for in
    [lo, hi] (0 < lo <= centre <= hi): ``holds(values) -> [result]`` (a batch; a result is
    true, or a tuple of what fails: empty where it holds). A scan of ``points`` values evenly in
    ln, then bisection of each edge in ln to ``resolution``. Returns (lower Edge, upper Edge),
    or None where ``centre`` itself fails."""
    grid = sorted(set(np.exp(np.linspace(math.log(lo), math.log(hi), points)).tolist()) | {centre})
    res = _ok_and_why(holds(grid))
    i = grid.index(centre)
    if not res[i][0]:
        return None
    sides: list[list] = []
    for step in (-1, 1):
        j = i
        while 0 <= j + step < len(grid) and res[j + step][0]:
            j += step
        if not 0 <= j + step < len(grid):
            sides.append([grid[j], None, ()])
        else:
            sides.append([grid[j], grid[j + step], res[j + step][1]])
    while True:
        todo = [s for s in sides if s[1] is not None and abs(math.log(s[1] / s[0])) > resolution]
        if not todo:
            break
        mids = [math.sqrt(s[0] * s[1]) for s in todo]
        for s, m, (ok, why) in zip(todo, mids, _ok_and_why(holds(mids))):
            if ok:
                s[0] = m
            else:
                s[1], s[2] = m, why
    return tuple(Edge(s[0], s[1] is None, tuple(s[2])) for s in sides)


def _ok_and_why(results) -> list:
    return [(r, ()) if isinstance(r, bool) else (not r, tuple(r)) for r in results]


def set_parameters(overrides) -> tuple:
    """The numeric keys the set ``overrides`` gives, at values > 0, as FitParameters whose
    bounds are the scan's range (module doc), with their values (SI): ((FitParameter, value)...)."""
    values = scene_io.load(fig3.GRAVITY, list(overrides)).values
    out = []
    for item in overrides:
        key = item.split("=", 1)[0].strip()
        spec = key_spec(key)
        if not (spec is float or isinstance(spec, str)):
            continue
        v = scene_value(values, key)
        if v is None or not v > 0:
            continue
        lo, hi = v / SCAN_FACTOR, v * SCAN_FACTOR
        law = PARAMETERS.get(key.split(".", 1)[1]) if key.startswith("chain.") else None
        if law is not None:
            lo, hi = max(lo, law.lo), min(hi, law.hi)
        out.append((FitParameter(key, lo, hi, "1" if spec is float else str(spec)), float(v)))
    if not out:
        raise invalid("--set", list(overrides), "no numeric key at a value > 0 to take sensitivities to")
    return tuple(out)


class Figures:
    """The targets' figures (fig3.TARGETS) of the Fig. 3 shots at candidate values of the set's
    keys, candidates solved in one batch (an ObservationObjective without observed values)."""

    def __init__(self, overrides):
        self.overrides = tuple(overrides)
        self.params = set_parameters(self.overrides)
        figures = tuple(t.figure for t in fig3.TARGETS)
        self.objective = ObservationObjective(fig3.GRAVITY, tuple(p for p, _ in self.params), figures, self.overrides)
        self.centre = np.array([v for _, v in self.params])
        self.solved = 0

    def at(self, thetas) -> list:
        self.solved += len(thetas)
        return self.objective.evaluate([np.asarray(t, dtype=float) for t in thetas])

    def moved(self, k: int, values) -> list:
        """The figures with key ``k`` at each of ``values``, the others at the set."""
        thetas = []
        for v in values:
            t = self.centre.copy()
            t[k] = v
            thetas.append(t)
        return self.at(thetas)


def failing(figures) -> tuple:
    """The names of the targets the figures miss."""
    return tuple(t.name for t, f in zip(fig3.TARGETS, figures) if not t.holds(f))


def sensitivities(fig: Figures) -> dict:
    """{"figures": {target: value at the set}, "holds": {target: bool}, "d_ln_figure_d_ln_p":
    {target: {key: value or None}}, "counts": {count target: {key: [at down, at the set, at
    up]}} (a count's jumps), "steps": {key: [down, up] values used}}."""
    base = fig.at([fig.centre])[0]
    thetas, steps = [], {}
    for k, (p, v) in enumerate(fig.params):
        up, down = min(v * math.exp(STEP), p.hi), max(v * math.exp(-STEP), p.lo)
        steps[p.key] = [down, up]
        for x in (down, up):
            t = fig.centre.copy()
            t[k] = x
            thetas.append(t)
    models = fig.at(thetas)
    sens: dict[str, dict] = {t.name: {} for t in fig3.TARGETS}
    counts: dict[str, dict] = {t.name: {} for t in fig3.TARGETS if t.figure.kind == "pulses"}
    for k, (p, _v) in enumerate(fig.params):
        down, up = steps[p.key]
        f_down, f_up = models[2 * k], models[2 * k + 1]
        for i, t in enumerate(fig3.TARGETS):
            if t.name in counts:
                counts[t.name][p.key] = [_count(f_down[i]), _count(base[i]), _count(f_up[i])]
            ok = f_down[i] > 0 and f_up[i] > 0 and math.isfinite(f_down[i]) and math.isfinite(f_up[i])
            sens[t.name][p.key] = float(math.log(f_up[i] / f_down[i]) / math.log(up / down)) if ok else None
    return {"figures": {t.name: (float(f) if math.isfinite(f) else None) for t, f in zip(fig3.TARGETS, base)},
            "holds": {t.name: t.holds(f) for t, f in zip(fig3.TARGETS, base)},
            "d_ln_figure_d_ln_p": sens, "counts": counts, "steps": steps}


def _count(value: float):
    return int(value) if math.isfinite(value) else None


def windows(fig: Figures, progress=None) -> dict:
    """{key: {"value", "scan": [lo, hi], "window": [lo, hi] or None, "open": [bool, bool],
    "failing_below", "failing_above"}} (module doc)."""
    tell = progress or (lambda text: None)
    out = {}
    for k, (p, v) in enumerate(fig.params):
        edges = window(lambda xs, k=k: [failing(f) for f in fig.moved(k, xs)], v, p.lo, p.hi)
        row = {"value": v, "unit": p.unit, "scan": [p.lo, p.hi]}
        if edges is None:
            row.update(window=None, open=None, failing_below=None, failing_above=None)
        else:
            row.update(window=[edges[0].value, edges[1].value], open=[edges[0].open, edges[1].open],
                       failing_below=list(edges[0].failing), failing_above=list(edges[1].failing))
        out[p.key] = row
        tell(f"window of {p.key}: {row['window']}")
    return out


def study(overrides=fig3.PARAMETER_SET, progress=None) -> dict:
    """Sensitivities and windows at ``overrides`` (module doc), with the targets and numerics."""
    fig = Figures(overrides)
    if progress:
        progress("sensitivities")
    result = sensitivities(fig)
    result["windows"] = windows(fig, progress)
    result.update(parameter_set=list(fig.overrides), step_ln=STEP, scan_factor=SCAN_FACTOR, scan_points=SCAN_POINTS,
                  resolution_ln=RESOLUTION, candidates_solved=fig.solved,
                  targets=[{"name": t.name, "lo": t.lo if math.isfinite(t.lo) else None,
                            "hi": t.hi if math.isfinite(t.hi) else None, "unit": t.figure.unit, "meaning": t.meaning}
                           for t in fig3.TARGETS])
    if not all(result["holds"].values()):
        missed = [k for k, ok in result["holds"].items() if not ok]
        result["note"] = f"the set misses {', '.join(missed)}: no window (each is measured from the set's value)"
    return result


def table(result: dict) -> str:
    """sensitivity.md: the figures and targets, the sensitivity matrix, the windows."""
    keys = list(result["steps"])
    lines = ["# Fig. 3 figures' sensitivity at " + ", ".join(result["parameter_set"]), "",
             "| target | range | at the set | holds |", "|---|---|---|---|"]
    for t in result["targets"]:
        lo, hi = ("-inf" if t["lo"] is None else f"{t['lo']:.4g}"), ("inf" if t["hi"] is None else f"{t['hi']:.4g}")
        rng = f"{lo} .. {hi}"
        v = result["figures"][t["name"]]
        unit = "" if t["unit"] == "1" else " " + t["unit"]
        lines.append(f"| {t['name']} | {rng}{unit} | {'n/a' if v is None else f'{v:.4g}'} "
                     f"| {'yes' if result['holds'][t['name']] else 'NO'} |")
    lines += ["", (f"d ln(figure) / d ln(p), central differences at p e^(+-{result['step_ln']}) "
                   "(a count of pulses is a step function: where a step crosses a jump, "
                   "its counts at p e^-step / p / p e^+step):"), "",
              "| target | " + " | ".join(keys) + " |", "|---" * (len(keys) + 1) + "|"]
    for name, row in result["d_ln_figure_d_ln_p"].items():
        jumps = result["counts"].get(name)
        cells = [f"count {'/'.join(map(str, jumps[k]))}" if jumps and jumps[k][0] != jumps[k][2]
                 else "n/a" if row[k] is None else f"{row[k]:+.3g}" for k in keys]
        lines.append(f"| {name} | " + " | ".join(cells) + " |")
    lines += ["", (f"Windows (others fixed; scan of {result['scan_points']} values over p/{result['scan_factor']:g}"
                   f" .. p x {result['scan_factor']:g}, edges bisected to {result['resolution_ln']:.0%} in ln p):"), "",
              "| key | value | window | fails below | fails above |", "|---|---|---|---|---|"]
    for key, w in result["windows"].items():
        u = "" if w["unit"] == "1" else " " + w["unit"]
        if w["window"] is None:
            lines.append(f"| {key} | {w['value']:.4g}{u} | none: the set misses a target | | |")
            continue
        lo = ("<= " if w["open"][0] else "") + f"{w['window'][0]:.4g}"
        hi = (">= " if w["open"][1] else "") + f"{w['window'][1]:.4g}"
        lines.append(f"| {key} | {w['value']:.4g}{u} | {lo} .. {hi}{u} | {', '.join(w['failing_below']) or '-'} "
                     f"| {', '.join(w['failing_above']) or '-'} |")
    return "\n".join(lines) + "\n"
