"""The accuracy contract, measured (``rig bench accuracy``): for the solver benchmark's two
1000-bead problems and every published scene's whole record, at accuracy 1e-3, 1e-4 (the
default), 1e-5 and 1e-6, the delivered error (the largest error of any recorded force
relative to its dynamic peak, against a converged reference), the solution's own
a-posteriori estimate, the steps and the CPU time of the whole controlled solve. The
contract: the error lies in [setting / 10, setting] and the estimate within a factor 3 of
it. The reference is solved at tau / REFERENCE_DIVISION with the head resolved alike; its
own error is bounded by comparing it with a solve at half its step (``reference_check``).
The table of docs/solver.md."""
from __future__ import annotations

import time

from rig.bench.baseline import machine
from rig.bench.problems import PROBE, SCENARIOS
from rig.bench.problems import chain as bench_chain
from rig.solver.problem import ChainProblem
from rig.solver.saveat import SaveAt
from rig.solver.solution import relative_error
from rig.solver.solve import solve
from rig.solver.stepsize import DEFAULT_ACCURACY, contact_time_scale, head_contacts, stepping_at

SCENES = ("ptfe52_gravity", "ptfe52_magnetic", "ptfe52_magnetic_4p25", "ptfe20_gravity",
          "steel21_gravity", "steel21_magnetic")
SETTINGS = (1e-3, 1e-4, 1e-5, 1e-6)
REFERENCE_DIVISION = 1000
QUICK: dict = dict(cases=("ptfe52_magnetic", "steel21_magnetic"), settings=(1e-3, 1e-4))


def cases(names=None):
    """(name, problem, save, t_end) of every contract case: the benchmark problems (the
    probe at contact 500 on a 1 MS/s grid) and the published scenes (their gauges' contacts
    and the wall, on their own grid, for their whole duration)."""
    from rig.bench.kernel_cost import SAMPLE_INTERVAL
    from rig.experiment.shot import Rig

    for name, (top, t_end) in SCENARIOS.items():
        if names is None or name in names:
            c = bench_chain(top)
            yield name, ChainProblem.from_chain(c), SaveAt({"c500": c.contact_probe(PROBE)}, SAMPLE_INTERVAL), t_end
    for scene in SCENES:
        if names is None or scene in names:
            rig = Rig.from_scene(scene)
            yield scene, ChainProblem.from_chain(rig.chain), rig.save_at(), rig.solver.duration


def reference(p, t_end: float, save: SaveAt, division: int = REFERENCE_DIVISION) -> dict:
    """The converged reference forces: the outer step tau / division, the head resolved."""
    tau = contact_time_scale(p, head_contacts(p) + 1)
    return solve(p, t_end, save=save, dt=stepping_at(p, tau / division), estimate=False).forces


def run(quick: bool = False, progress=None) -> dict:
    names = QUICK["cases"] if quick else None
    settings = QUICK["settings"] if quick else SETTINGS
    rows, checks = [], {}
    for name, p, save, t_end in cases(names):
        if progress:
            progress(f"{name}: reference")
        ref = reference(p, t_end, save)
        checks[name] = relative_error(reference(p, t_end, save, REFERENCE_DIVISION // 2), ref)
        for acc in settings:
            if progress:
                progress(f"{name}: accuracy {acc:g}")
            t0 = time.process_time()
            sol = solve(p, t_end, save=save, accuracy=acc)
            cpu = time.process_time() - t0
            rows.append({"case": name, "setting": acc, "error": relative_error(sol.forces, ref),
                         "estimate": sol.stats.error_estimate, "steps": sol.stats.steps, "cpu_s": cpu,
                         "dt_s": sol.stats.dt_s, "attempts": sol.stats.attempts,
                         "single_solve_cpu_s": _single_cpu(p, t_end, save, sol.stats.dt_s),
                         "estimate_from_2dt": _coarse_estimate(p, t_end, save, sol)})
    return {"rows": rows, "reference_check": checks, "machine": machine()}


def _single_cpu(p, t_end, save, dt) -> float:
    """CPU (s) of one solve at the control's final step, no estimate: what the contract adds to."""
    t0 = time.process_time()
    solve(p, t_end, save=save, dt=stepping_at(p, dt), estimate=False)
    return time.process_time() - t0


def _coarse_estimate(p, t_end, save, sol) -> float:
    """The estimate a companion at twice the step would give (Richardson with R = 2^3): the
    half-price alternative the control does not use (docs/solver.md)."""
    coarse = solve(p, t_end, save=save, dt=stepping_at(p, 2 * sol.stats.dt_s), estimate=False)
    return relative_error(coarse.forces, sol.forces) / (2.0**3 - 1.0)


def holds(row: dict) -> tuple:
    """(error within [setting / 10, setting], estimate within a factor 3 of the error)."""
    e, s, est = row["error"], row["setting"], row["estimate"]
    return s / 10 <= e <= s, est is not None and e > 0 and 1 / 3 <= est / e <= 3


def table(r: dict) -> str:
    head = ("| case | setting | error | estimate | est/error | steps | dt (ns) | solves | CPU (s) | "
            "in [s/10, s] | estimate within 3x |")
    lines = [head, "|---" * 11 + "|"]
    for row in r["rows"]:
        inside, close = holds(row)
        est = row["estimate"]
        mark = " (default)" if row["setting"] == DEFAULT_ACCURACY else ""
        est_txt = "-" if est is None else f"{est:.2e}"
        ratio_txt = "-" if est is None or row["error"] == 0 else f"{est / row['error']:.2f}"
        lines.append(f"| {row['case']} | {row['setting']:.0e}{mark} | {row['error']:.2e} | {est_txt} | {ratio_txt} | "
                     f"{row['steps']} | {row['dt_s'] * 1e9:.0f} | {row['attempts']} | {row['cpu_s']:.3f} | "
                     f"{'yes' if inside else 'NO'} | {'yes' if close else 'NO'} |")
    n = len(r["rows"])
    inside = sum(holds(row)[0] for row in r["rows"])
    close = sum(holds(row)[1] for row in r["rows"])
    lines.append("")
    coarse = sum(1 / 3 <= row["estimate_from_2dt"] / row["error"] <= 3 for row in r["rows"] if row["error"] > 0)
    cost = [row["cpu_s"] / row["single_solve_cpu_s"] for row in r["rows"] if row["single_solve_cpu_s"] > 0]
    lines.append(f"error within [setting/10, setting]: {inside} of {n}; estimate within 3x of the error: "
                 f"{close} of {n} (a companion at 2 dt instead, Richardson R = 8: {coarse} of {n})")
    lines.append(f"the controlled solve costs {sorted(cost)[len(cost) // 2]:.1f} (median; "
                 f"{min(cost):.1f} to {max(cost):.1f}) times one solve at its final step")
    lines.append("reference check (reference against one at twice its step): " + ", ".join(
        f"{k} {v:.1e}" for k, v in r["reference_check"].items()))
    lines.append(f"machine: {r['machine']} (the CPU column is this machine's)")
    return "\n".join(lines)
