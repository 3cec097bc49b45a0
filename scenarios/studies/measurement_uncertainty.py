"""How far the measured speed and amplitude fall from the truth with the default
instrument errors (gauge position sd 1 mm, gain sd 5%, gauge noise 1 mV, scope noise
0.2 mV), over many seeds of each published scene; peak-to-peak against cross-correlation.

    python scenarios/studies/measurement_uncertainty.py [--seeds 200] [--set KEY=VALUE ...]

Public API only: rig.experiment.shot.Rig and rig.experiment.measure.shot_blocks.
"""
import argparse

import numpy as np

from rig.experiment.measure import shot_blocks
from rig.experiment.shot import Rig

SCENES = ["ptfe52_gravity", "ptfe52_magnetic", "ptfe52_magnetic_4p25", "ptfe20_gravity",
          "steel21_gravity", "steel21_magnetic"]


def study(scene: str, seeds: int, overrides=()) -> dict:
    rig = Rig.from_scene(scene, overrides)
    truth = rig.truth_analysis()
    rows = []
    for seed in range(seeds):
        m = shot_blocks(rig, rig.fire(seed=seed))["measured"]
        rows.append((m["speed_m_per_s"], m["speed_xcorr_m_per_s"], m["amplitude_N"]))
    v, vx, a = (np.array([r[k] for r in rows], dtype=float) for k in range(3))
    rel = lambda x, ref: x / ref - 1  # noqa: E731
    return {"scene": scene, "speed": rel(v, truth.speed_m_per_s), "xcorr": rel(vx, truth.speed_m_per_s),
            "amplitude": rel(a, truth.amplitude_N)}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=200)
    ap.add_argument("--set", action="append", default=[], help="scene override, applied to every scene")
    args = ap.parse_args()
    n = args.seeds
    print(f"measured / truth - 1 over {n} seeds{' with ' + ', '.join(args.set) if args.set else ''}: "
          f"mean +- sd (%)\n")
    print("| scene | speed, peak-to-peak | speed, cross-correlation | amplitude F_d |")
    print("|---|---|---|---|")
    for scene in SCENES:
        r = study(scene, n, args.set)
        cell = lambda x: f"{100 * np.nanmean(x):+.2f} +- {100 * np.nanstd(x):.2f}"  # noqa: E731
        print(f"| {scene} | {cell(r['speed'])} | {cell(r['xcorr'])} | {cell(r['amplitude'])} |")


if __name__ == "__main__":
    main()
