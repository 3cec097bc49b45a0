"""Pipeline benchmark (``rig bench pipeline``): the full analysis (baseline, RC inversion,
calibration, pulses, widths, both times of flight, train count) of one 3-channel,
10,000-point scope record of ptfe52_magnetic. Median of 51 runs."""
from __future__ import annotations

import statistics
import time

from instruments.analysis import analyze_record
from rig.experiment.measure import midway_static_force, setup_for
from rig.experiment.shot import Rig


def run(repeats: int = 51) -> dict:
    rig = Rig.from_scene("ptfe52_magnetic", ["scope.record_length=10000"])
    shot = rig.fire(seed=1)
    setup = setup_for(rig, rig.truth_analysis().beta, midway_static_force(rig))
    analyze_record(shot.scope, setup)
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        analyze_record(shot.scope, setup)
        times.append(time.perf_counter() - t0)
    w = shot.scope["CH1"]
    return {"channels": len(shot.scope.waveforms), "points": w.preamble.points,
            "median_s": statistics.median(times), "min_s": min(times), "repeats": repeats}


def table(r: dict) -> str:
    return (f"analysis of a {r['channels']}-channel, {r['points']}-point record: median "
            f"{r['median_s'] * 1e3:.2f} ms (min {r['min_s'] * 1e3:.2f} ms, {r['repeats']} runs)")
