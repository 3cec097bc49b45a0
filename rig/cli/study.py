"""`rig mc`: a Monte Carlo study over many virtual shots."""
from __future__ import annotations

import sys

from rig.cli.common import check_size, compile_cold, progress_bar, scene_overrides, writing_to
from rig.errors import invalid


def cmd_mc(args) -> dict:
    """Parse the study, run it with a progress bar, print its summary."""
    from rig.experiment.scene import load

    remote = args.scheduler not in (None, "local")
    if args.worker_timeout is not None and not args.scheduler:
        raise invalid("--worker-timeout", args.worker_timeout, "needs --scheduler (it watches the Dask workers)")
    if args.workers is not None and remote:
        raise invalid("--workers", args.workers, f"the workers of --scheduler {args.scheduler} are the cluster's; "
                                                 "--workers sizes a local run or --scheduler local")
    load(args.scene, scene_overrides(args))  # a bad scene stops here, before numba is loaded
    from rig.study.distributions import parse_vary
    from rig.study.executors import DEFAULT_WORKER_TIMEOUT
    from rig.study.mc_run import run_in
    from rig.study.mc_spec import DEFAULT_BATCH, MonteCarloStudy
    from rig.study.sobol import sobol_shots
    from rig.study.store import Store

    dists = tuple(parse_vary(args.vary or []))
    shots = args.shots
    batch = args.batch or Store.stored_batch(args.out) or DEFAULT_BATCH  # a study resumed keeps its batches
    if args.sobol:
        shots = sobol_shots(args.shots, len(dists))
    study = MonteCarloStudy(args.scene, dists, shots, args.seed, tuple(args.set or ()), batch, args.accuracy,
                  args.sobol, args.truth, args.window, args.traces)
    from rig.study.nominal import nominal

    with writing_to(args.out), Store(args.out, study).held() as store:  # held before anything is printed
        if shots != args.shots and not args.json:
            print(f"Sobol design over {len(dists)} inputs: {shots} shots "
                  f"({shots // (len(dists) + 2)} x {len(dists) + 2})", file=sys.stderr)
        held = min(study.batch, study.shots)  # the shots a batch holds at once
        compile_cold("mc", "study", args.quiet)
        rig = nominal(study.scene, study.overrides).rig
        rig.check_record()  # settings that can give no record (or a made-up one) are refused before any solve
        whole = rig.estimate(controlled=False).times(study.shots, held)
        check_size(whole, args, f"the study's {study.shots} shots (batches of {held} held at once)")
        with progress_bar(args.quiet, total=study.shots, desc="mc", unit="shot") as bar:
            run = run_in(store, study, args.workers or 1, args.scheduler, bar.update, bar.update,
                         args.worker_timeout or DEFAULT_WORKER_TIMEOUT)
    if not args.json:
        print_study(run.report, run.ran_now, args.out)
    failed = run.report["failed"]
    if failed["share"] > args.max_failed:
        print(f"rig mc: error: {failed['count']} of {run.report['shots']} shots failed "
              f"({failed['share']:.1%}, more than --max-failed {args.max_failed:.1%}): "
              + "; ".join(f"{n} {why}" for why, n in failed["reasons"].items()), file=sys.stderr)
        args.exit_code = 1
    return run.report


def print_study(report: dict, ran: int, out):
    print(f"{report['shots']} shots ({ran} run now"
          + (f", {report['shots_per_s']:.0f} shots/s" if ran else "") + f") in {out}")
    for key, label in (("speed_m_per_s", "speed V_s (m/s)"), ("amplitude_N", "amplitude F_d (N)")):
        r = report[key]
        if r["estimate"] is not None:
            print(f"  {label:20s} {r['estimate']:.4g} +- {r['std']:.3g}  95%: [{r['ci95'][0]:.4g}, "
                  f"{r['ci95'][1]:.4g}]  {'stable' if r['converged'] else 'not yet stable'} "
                  f"(JCGM 101, tolerance {r['tolerance']:.2g})")
    for key, s in report.get("sobol", {}).items():
        print(f"  Sobol {key} ({s['base_samples']} base samples): dominant input {s['dominant']}; total "
              + ", ".join(f"{k} {v:.2f}+-{s['total_conf95'][k]:.2f}" for k, v in s["total"].items()))
    failed = report["failed"]
    if failed["count"]:
        print(f"  failed: {failed['count']} of {report['shots']} shots ({failed['share']:.1%}), left out of "
              "the estimates: " + "; ".join(f"{n} {why}" for why, n in failed["reasons"].items()))
    print("  wrote study.h5, report.json, histograms.png, speed_vs_amplitude.png")
