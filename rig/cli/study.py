"""`rig mc`: a Monte Carlo study over many virtual shots."""
from __future__ import annotations

import json
import sys
from pathlib import Path

from rig.errors import RigError


def cmd_mc(args) -> dict:
    from rig.experiment.scene import load

    load(args.scene, args.set or ())  # a bad scene stops here, before numba is loaded
    import time

    import numpy as np
    from tqdm import tqdm

    from rig.study.distributions import parse_vary
    from rig.study.executors import run_study
    from rig.study.montecarlo import Store, Study, nominal_rig
    from rig.study.report import figures, jcgm101, sobol_indices
    from rig.theory.longwave import solitary_wave_speed

    dists = tuple(parse_vary(args.vary or []))
    shots = args.shots
    if args.sobol:
        from rig.study.montecarlo import sobol_shots

        shots = sobol_shots(args.shots, len(dists))
        if shots != args.shots and not args.json:
            print(f"Sobol design over {len(dists)} inputs: {shots} shots "
                  f"({shots // (len(dists) + 2)} x {len(dists) + 2})", file=sys.stderr)
    study = Study(args.scene, dists, shots, args.seed, tuple(args.set or ()), args.batch, args.accuracy,
                  args.sobol, args.truth, args.window, args.traces)
    if not study.dists:
        raise RigError("--vary: give at least one uncertain input, e.g. striker.velocity=\"normal(0.89 m/s, 0.01 m/s)\"")
    base = nominal_rig(study.scene, study.overrides)  # the scene must be valid before any shot
    for d in study.dists:
        parts = d.key.split(".")
        names = [g.name for g in base.gauges]
        if parts[0] == "gauges" and parts[1] not in names:
            raise RigError(f"--vary {d.key}: the scene has no gauge {parts[1]!r} (gauges: {', '.join(names)})")
    if study.sobol:
        from rig.study.montecarlo import sobol_matrix

        sobol_matrix(study)
    store = Store(args.out, study).open()
    done = sum(len(study.shots_of(b)) for b in store.done())
    t0 = time.perf_counter()
    with tqdm(total=study.shots, initial=done, desc="mc", unit="shot", file=sys.stderr,
              disable=args.quiet) as bar:
        try:
            run_study(study, store, args.workers, args.scheduler, bar.update)
        except KeyboardInterrupt:
            kept = sum(len(study.shots_of(b)) for b in store.done())
            raise RigError(f"interrupted: {kept} of {study.shots} shots are kept in {args.out}; "
                           f"run the same command again to resume") from None
    ran = study.shots - done
    elapsed = time.perf_counter() - t0
    results = store.collect()
    out = results["outputs"]
    report = {"shots": int(results["index"].size), "shots_per_s": ran / elapsed if ran else None,
              "speed_m_per_s": jcgm101(out["speed_m_per_s"]),
              "speed_xcorr_m_per_s": jcgm101(out["speed_xcorr_m_per_s"]),
              "amplitude_N": jcgm101(out["amplitude_N"]),
              "truth_speed_m_per_s": jcgm101(out["truth_speed_m_per_s"]),
              "truth_amplitude_N": jcgm101(out["truth_amplitude_N"]),
              "inputs": {d.key: d.text() for d in study.dists}}
    if study.sobol:
        report["sobol"] = {k: sobol_indices(study, results["inputs"], out[k]) for k in ("speed_m_per_s", "amplitude_N")}
    from rig.experiment.measure import midway_static_force

    F0 = midway_static_force(base)
    m = base.chain.beads[-1].material
    F = np.linspace(max(np.nanmin(out["amplitude_N"]) * 0.8, 1e-3), np.nanmax(out["amplitude_N"]) * 1.2, 100)
    figures(Path(args.out), results, study.keys,
            (F, solitary_wave_speed(m.E, m.nu, m.rho, base.chain.beads[-1].diameter, F0, F0 + F),
             f"Eq (1), F_0 = {F0:.3g} N"))
    store.consolidate(results, report)
    (Path(args.out) / "report.json").write_text(json.dumps(report, indent=1))
    if not args.json:
        print(f"{report['shots']} shots ({ran} run now"
              + (f", {report['shots_per_s']:.0f} shots/s" if ran else "") + f") in {args.out}")
        for key, label in (("speed_m_per_s", "speed V_s (m/s)"), ("amplitude_N", "amplitude F_d (N)")):
            r = report[key]
            if r["estimate"] is not None:
                print(f"  {label:20s} {r['estimate']:.4g} +- {r['std']:.3g}  95%: [{r['ci95'][0]:.4g}, "
                      f"{r['ci95'][1]:.4g}]  {'stable' if r['converged'] else 'not yet stable'} "
                      f"(JCGM 101, tolerance {r['tolerance']:.2g})")
        for key, s in report.get("sobol", {}).items():
            print(f"  Sobol {key} ({s['base_samples']} base samples): dominant input {s['dominant']}; total "
                  + ", ".join(f"{k} {v:.2f}+-{s['total_conf95'][k]:.2f}" for k, v in s["total"].items()))
        print("  wrote study.h5, report.json, histograms.png, speed_vs_amplitude.png")
    return report
