"""Accuracy setting on the published scenes (``rig bench accuracy``): for each scene and
accuracy 1e-3, 1e-4 (the default) and 1e-5, the largest error of any recorded force
relative to its peak against a single-rate solve at dt = tau/300, over the first crossing
(until the wall force first peaks) and over the whole record, and the outer step taken.
The table of docs/solver.md."""
from __future__ import annotations

import numpy as np

from rig.experiment.shot import Rig
from rig.solver.problem import ChainProblem
from rig.solver.solve import solve
from rig.solver.stepsize import DEFAULT_ACCURACY, contact_time_scale

SCENES = ("ptfe52_gravity", "ptfe52_magnetic", "ptfe52_magnetic_4p25", "ptfe20_gravity",
          "steel21_gravity", "steel21_magnetic")
ACCURACIES = (1e-3, 1e-4, 1e-5)


def _first_wall_peak(wall: np.ndarray) -> int:
    i = int(np.argmax(wall > 0.5 * wall.max()))
    while i + 1 < wall.size and wall[i + 1] >= wall[i]:
        i += 1
    return i


def run(scenes=SCENES) -> dict:
    rows = {}
    for scene in scenes:
        rig = Rig.from_scene(scene)
        p = ChainProblem.from_chain(rig.chain)
        save = rig.save_at()
        t_end = rig.solver.duration
        ref = solve(p, t_end, save=save, dt=contact_time_scale(p) / 300)
        first = _first_wall_peak(ref.forces["wall"])
        rows[scene] = []
        for acc in ACCURACIES:
            sol = solve(p, t_end, save=save, accuracy=acc)
            err = {name: np.abs(sol.forces[name] - ref.forces[name]) / np.max(np.abs(ref.forces[name]))
                   for name in ref.forces}
            rows[scene].append({"accuracy": acc, "dt_s": sol.stats.dt_s,
                                "first_crossing": float(max(e[:first].max() for e in err.values())),
                                "whole_record": float(max(e.max() for e in err.values()))})
    return {"rows": rows}


def table(r: dict) -> str:
    head = [f"accuracy {a:.0e}{' (default)' if a == DEFAULT_ACCURACY else ''} first / whole" for a in ACCURACIES]
    lines = ["| scene | " + " | ".join(head) + " |",
             "|---" * (len(ACCURACIES) + 1) + "|"]
    for scene, cells in r["rows"].items():
        lines.append(f"| {scene} | " + " | ".join(
            f"{c['first_crossing']:.1e} / {c['whole_record']:.1e} ({c['dt_s'] * 1e9:.0f} ns)" for c in cells) + " |")
    return "\n".join(lines)
