"""Benchmark of ``rig fit`` on the ten Table-1 points (``rig bench fit``): the whole command,
start-up included, must take under a minute on 2 cores.

Each model of ``rig reproduce daraio2006 --fitted`` (Hertz with E; power law with E and n;
power law and dashpot) fitted by the command line in a fresh interpreter and a fresh
output folder (no resume cache), rounds interleaved; medians of wall time and of CPU time
(the children's user + system). Baseline in the same rounds: one evaluation of the
objective (``rig fit ... --max-evaluations 1``: start-up, the model curves at the start
values and the first Jacobian's, one batched solve), so the ratio says how many such
evaluations a fit costs. "solved": candidates the fit solved; "error est.": the companion
estimate of the model's error at the fit's result (its "numerics"), against the scene's
accuracy setting 1e-4.
"""
from __future__ import annotations

import json
import statistics
import sys
import tempfile
from importlib import resources
from pathlib import Path

from rig.bench.startup import RIG, timed_child
from rig.study.fitted_families import FAMILIES

MODELS = {"hertz": list(FAMILIES[0].params), "power law": list(FAMILIES[1].params),
          "power law + dashpot": list(FAMILIES[2].params)}
"""The three models timed: the first three families of `rig reproduce daraio2006 --fitted`."""

ROUNDS = 3
LIMIT_S = 60.0


def _command(bounds: list, points: Path, out: Path, max_evaluations: int | None = None) -> list:
    cmd = [sys.executable, "-c", RIG, "fit", "ptfe52_gravity", "--points", str(points), "--out", str(out),
           "--quiet", "--json"]
    for b in bounds:
        cmd += ["--param", b]
    if max_evaluations:
        cmd += ["--max-evaluations", str(max_evaluations)]
    return cmd


def _timed(cmd: list) -> tuple:
    """(wall s, CPU s of the child, its JSON block or None)."""
    wall, cpu, out = timed_child(cmd, check=False)  # a fit that does not converge exits 1: still timed
    try:
        return wall, cpu, json.loads(out)
    except json.JSONDecodeError:
        return wall, cpu, None


def run(quick: bool = False, progress=None) -> dict:
    rounds = 1 if quick else ROUNDS
    cases = {"one evaluation (baseline)": (MODELS["power law"], 1)} | {
        f"{name} ({len(bounds)} parameters)": (bounds, None) for name, bounds in MODELS.items()}
    times: dict[str, list] = {name: [] for name in cases}
    blocks: dict = {}
    csv = resources.files("rig") / "scenes" / "daraio2006" / "table1_experiment.csv"
    with resources.as_file(csv) as points, tempfile.TemporaryDirectory() as tmp:
        for k in range(rounds):
            for j, (name, (bounds, max_ev)) in enumerate(cases.items()):
                if progress:
                    progress(f"round {k + 1} of {rounds}: {name}")
                wall, cpu, block = _timed(_command(bounds, points, Path(tmp) / f"r{k}c{j}", max_ev))
                times[name].append((wall, cpu))
                blocks.setdefault(name, block)
    base = statistics.median(c for _, c in times["one evaluation (baseline)"])
    rows = []
    for name, ts in times.items():
        b = blocks[name] or {}
        cpu = statistics.median(c for _, c in ts)
        rows.append(dict(fit=name, wall_s=statistics.median(w for w, _ in ts), cpu_s=cpu, ratio_to_baseline=cpu / base,
                         evaluations=b.get("evaluations"), converged=b.get("converged"),
                         rms_relative=b.get("residual_rms_relative"),
                         error_estimate=(b.get("numerics") or {}).get("estimate_at_fit"),
                         estimates={k: v["estimate"] for k, v in b.get("parameters", {}).items()}))
    return dict(rounds=rounds, limit_s=LIMIT_S, rows=rows)


def table(r: dict) -> str:
    head = (f"{'fit of the ten Table-1 points':34s} {'wall s':>7s} {'CPU s':>7s} {'x base':>7s} {'solved':>7s} "
            f"{'RMS':>6s} {'error est.':>10s}")
    lines = [f"rig fit ptfe52_gravity --points table1_experiment.csv, fresh interpreter and folder, medians of "
             f"{r['rounds']} interleaved rounds (limit {r['limit_s']:g} s)", head, "-" * len(head)]
    for x in r["rows"]:
        rms = "-" if x["rms_relative"] is None else f"{x['rms_relative']:.1%}"
        solved = "-" if x["evaluations"] is None else str(x["evaluations"])
        est = "-" if x["error_estimate"] is None else f"{x['error_estimate']:.1e}"
        flag = "" if x["wall_s"] < r["limit_s"] else "  OVER THE LIMIT"
        lines.append(f"{x['fit']:34s} {x['wall_s']:7.1f} {x['cpu_s']:7.1f} {x['ratio_to_baseline']:7.1f} "
                     f"{solved:>7s} {rms:>6s} {est:>10s}{flag}")
    return "\n".join(lines)
