"""`rig mc`: a Monte Carlo study over many virtual shots."""
from __future__ import annotations

import contextlib
import sys

from rig.cli.common import (
    allow_large,
    check_size,
    command,
    compile_cold,
    count_arg,
    fraction_arg,
    plain,
    positive_seconds,
    progress_bar,
    scene_overrides,
    seed_arg,
    writing_to,
)
from rig.errors import invalid


def cmd_mc(args) -> dict:
    """Parse the study, run it (rig.study.mc_run) with a progress bar, print its summary."""
    from rig.experiment.scene import load

    remote = args.scheduler not in (None, "local")
    if args.worker_timeout is not None and not args.scheduler:
        raise invalid("--worker-timeout", args.worker_timeout, "needs --scheduler (it watches the Dask workers)")
    if args.workers is not None and remote:
        raise invalid("--workers", args.workers, f"the workers of --scheduler {args.scheduler} are the cluster's; "
                                                 "--workers sizes a local run or --scheduler local")
    load(args.scene, scene_overrides(args))  # a bad scene stops here, before numba is loaded
    import numba

    from rig.study.executors import DEFAULT_WORKER_TIMEOUT
    from rig.study.mc_run import described, run_to

    here = not args.scheduler and (args.workers or 1) == 1  # the batches run in this process, on numba's threads
    study = described(args.scene, args.vary or [], args.shots, args.out, args.seed, tuple(args.set or ()), args.batch,
                      args.accuracy, args.sobol, args.truth, args.window, args.traces,
                      numba.get_num_threads() if here else 1)

    def admit(cost):  # the folder held, before anything is solved
        if study.shots != args.shots and not args.json:
            keys = len(study.dists)
            print(f"Sobol design over {keys} inputs: {study.shots} shots ({study.shots // (keys + 2)} x {keys + 2})",
                  file=sys.stderr)
        compile_cold("mc", "study", args.quiet)
        check_size(cost(), args, f"the study's {study.shots} shots (batches of {min(study.batch, study.shots)} "
                                  "held at once)")

    with writing_to(args.out), contextlib.ExitStack() as shown:
        bar = []

        def on_start(done: int):  # the study admitted, its batches about to run: the bar from here
            bar.append(shown.enter_context(progress_bar(args.quiet, total=study.shots, desc="mc", unit="shot")))
            bar[0].update(done)

        run = run_to(args.out, study, args.workers or 1, args.scheduler, lambda n: bar[0].update(n), on_start,
                     args.worker_timeout or DEFAULT_WORKER_TIMEOUT, admit)
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


def add_mc(sub) -> None:
    """The parser of ``rig mc``."""
    mc = command(sub, "mc", "Monte Carlo study over many virtual shots", cmd_mc)
    mc.add_argument("scene")
    mc.add_argument("--shots", type=count_arg, required=True, help="number of shots (>= 1)")
    mc.add_argument("--vary", action="append", metavar="KEY=DIST",
                    help='e.g. striker.velocity="normal(0.89 m/s, 0.01 m/s)"; also chain.bead_mass, '
                         'gauges.NAME.gain, gauges.NAME.misalignment')
    mc.add_argument("--set", action="append", metavar="KEY=VALUE", help="fixed overrides")
    mc.add_argument("--seed", type=seed_arg, default=0, help="the study's seed (default 0)")
    mc.add_argument("--batch", type=count_arg, help="shots per batch (default 256, or 128 per numba thread up to "
                                                    "4096 where the study runs in this process on more than 2 numba "
                                                    "threads, within the memory limit; "
                                                    "resuming a study in --out: its own)")
    mc.add_argument("--accuracy", type=plain(float), help="solver accuracy (default: the scene's)")
    mc.add_argument("--workers", type=count_arg,
                    help="local worker processes, or with --scheduler local the cluster's (default 1: this "
                         "process, on every core through numba's threads; each worker starts an interpreter of its "
                         "own, about 2 s: workers run faster than one process's threads only on many cores and in "
                         "long studies)")
    mc.add_argument("--scheduler", help="Dask scheduler: tcp://HOST:PORT, or 'local' for a LocalCluster")
    mc.add_argument("--sobol", action="store_true", help="Sobol design and indices (needs SALib)")
    mc.add_argument("--truth", action="store_true", help="also analyse each shot's noise-free truth (slower)")
    mc.add_argument("--window", choices=["leading", "record"], default="leading",
                    help="simulate until the leading pulse has passed the last gauge (default), "
                         "or the scene's whole record")
    mc.add_argument("--traces", action="store_true",
                    help="also archive every shot's scope record and truth in DIR/traces/ (one archive per batch)")
    mc.add_argument("--out", required=True, metavar="DIR")
    mc.add_argument("--quiet", action="store_true", help="no progress bar")
    mc.add_argument("--max-failed", type=fraction_arg, default=0.05, metavar="PERCENT",
                    help="fail the study (exit 1) when more shots than this fail (default 5%%)")
    mc.add_argument("--worker-timeout", type=positive_seconds, metavar="SECONDS",
                    help="with --scheduler: stop when no Dask worker is alive for this long (default 300)")
    allow_large(mc)
