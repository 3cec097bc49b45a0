"""Virtual-shot benchmark (``rig bench shot``): one full shot of a published scene, split
into the solver and the instruments (gauges, wall sensor, oscilloscope). Each repeat
builds a fresh Rig, so the solver runs every time; medians over the repeats."""
from __future__ import annotations

import statistics
import time

from rig.experiment.shot import Rig


def run(scene: str = "ptfe52_magnetic", repeats: int = 21) -> dict:
    Rig.from_scene(scene).fire(seed=0)  # compile / load the kernels first
    solver, total = [], []
    for seed in range(repeats):
        rig = Rig.from_scene(scene)
        t0 = time.perf_counter()
        rig.solution()
        t1 = time.perf_counter()
        rig.fire(seed=seed)
        t2 = time.perf_counter()
        solver.append(t1 - t0)
        total.append(t2 - t0)
    s, t = statistics.median(solver), statistics.median(total)
    return {"scene": scene, "repeats": repeats, "shot_s": t, "solver_s": s,
            "instruments_s": t - s, "solver_share": s / t}


def table(r: dict) -> str:
    return "\n".join([
        f"virtual shot of {r['scene']} (median of {r['repeats']}, kernels compiled)",
        f"  {'stage':12s} {'ms':>8s} {'share':>7s}",
        f"  {'solver':12s} {r['solver_s'] * 1e3:8.2f} {r['solver_share']:7.0%}",
        f"  {'instruments':12s} {r['instruments_s'] * 1e3:8.2f} {1 - r['solver_share']:7.0%}",
        f"  {'full shot':12s} {r['shot_s'] * 1e3:8.2f}"])
