"""`rig sweep` and `rig reproduce`: one shot per value of a key, and the published study."""
from __future__ import annotations

from pathlib import Path

from rig.cli.common import (
    allow_large,
    check_archive_out,
    check_size,
    command,
    count_arg,
    flag_lines,
    folder_shown,
    missing_lines,
    progress_bar,
    scene_overrides,
    seed_arg,
    writing_to,
)
from rig.cli.fitting import global_search_arg, starts_arg
from rig.cli.shots import shot_summary
from rig.errors import Interrupted, RigError, invalid

MAX_SWEEP_POINTS = 10_000  # more needs --allow-large (each point's shot is kept to the end)


def cmd_sweep(args) -> dict:
    from rig.experiment.scene import load

    if len(args.vary) > 1:
        raise RigError(f"--vary given {len(args.vary)} times ({', '.join(v.split('=')[0] for v in args.vary)}): "
                       "a sweep varies one key; run one sweep per key")

    if args.out:
        check_archive_out(args.out, "--out")
    swept = args.vary[0].split("=", 1)[0].strip()
    overrides = scene_overrides(args, {swept: f"--vary {args.vary[0]}"})
    scene = load(args.scene, overrides)  # a bad scene stops here, before numba is loaded
    from rig.experiment.shot import Rig
    from rig.study.sweep import Vary, run_sweep

    vary = Vary.parse(args.vary[0], None if args.allow_large else MAX_SWEEP_POINTS)
    n = len(vary.values)
    check_size(Rig(scene).estimate().times(n, n), args, f"this sweep of {n} points")  # every point is kept
    with (progress_bar(args.quiet, total=len(vary.values), desc=f"sweep {vary.key}", unit="shot") as bar,
          writing_to(args.out or "the sweep")):
        fired = []

        def tick():
            fired.append(1)
            bar.update()

        try:
            points = run_sweep(args.scene, vary, overrides, args.seed, tick, args.out)
        except KeyboardInterrupt:
            kept = f"those points' shots are in {args.out}" if args.out else "nothing is kept (no --out)"
            raise Interrupted(f"interrupted after {len(fired)} of {n} points: {kept}") from None
    if all(p.shot is None for p in points):  # nothing measured: a failure, not a table of reasons
        raise RigError(f"no point of the sweep gave a record; point 1 of {n} ({vary.key} = {points[0].value:g}): "
                       f"{points[0].reason}")
    out: dict[str, list] = {"points": []}
    for p in points:
        if p.shot is None:
            one = {"scenario": p.rig.name, "seed": p.seed, "overrides": list(p.rig.scene.overrides),
                   "truth": None, "measured": None, "theory": None}
        else:
            one = shot_summary(p.rig, p.shot)
            one.update(p.blocks)
        one["value"], one["reason"] = p.value, p.reason
        out["points"].append(one)
    if not args.json:
        print_sweep(vary.key, out["points"])
        if args.out:
            print(f"appended {sum(p.shot is not None for p in points)} shots to {args.out}")
    return out


def print_sweep(key: str, points: list):
    """The sweep's table: truth, measured and Eq (1) per point, and under a point that has
    no measured speed, why (the analysis' reasons); a point that gave no record, why."""
    def fmt(v, spec):
        return "-".rjust(int(spec.split(".")[0])) if v is None else format(v, spec)
    print(f"{key:>18s} | {'truth F_d N':>11s} {'V_s m/s':>8s} | {'measured F_d N':>14s} "
          f"{'V_s m/s':>8s} | {'Eq (1) m/s':>10s}")
    clipped = []
    for p in points:
        t, m = p["truth"], p["measured"]
        if p["reason"] is not None:
            print(f"{p['value']:18.6g} | no record: {p['reason']}")
            continue
        if t is None:
            print(f"{p['value']:18.6g} | speeds and amplitudes need two gauge beads")
            continue
        chans = [k for k, v in p["channels"].items() if v["clipped"]]
        print(f"{p['value']:18.6g} | {fmt(t['amplitude_N'], '11.3f')} {fmt(t['speed_m_per_s'], '8.1f')} | "
              f"{fmt(m['amplitude_N'], '14.3f')} {fmt(m['speed_m_per_s'], '8.1f')} | "
              f"{fmt(p['theory']['speed_m_per_s'], '10.1f')}" + (f"  CLIPPED: {','.join(chans)}" if chans else ""))
        if m["speed_m_per_s"] is None:
            why = missing_lines(m["reasons"]) or [f"no result: {p['no_trigger_reason'] or 'no reason given'}"]
            print(f"{'':18s}   measured: {'; '.join(why)}")
        for line in flag_lines(t.get("flags", {})):  # the truth's flags hold for the measured figures too
            print(f"{'':18s}   {line}")
        clipped += [p["value"]] if chans else []
    if clipped:
        print(f"clipped scope channels at {key} = {', '.join(f'{v:g}' for v in clipped)}: a clipped "
              f"gauge channel gives no measured figure; raise scope.channels.CHn.volts_per_div")


def cmd_reproduce(args) -> dict:
    for flag, value in (("--draws", args.draws), ("--allow-large", args.allow_large or None)):
        if value is not None and not args.identifiability:
            raise invalid(flag, value, "only with --identifiability (the published study draws no noise)")
    if args.seed is not None and not (args.identifiability or args.global_search):
        raise invalid("--seed", args.seed, "only with --identifiability or --fitted --global-search (the published "
                                           "study draws no noise)")
    for flag, value, default in (("--starts", args.starts, 1), ("--global-search", args.global_search, 0)):
        if value != default and not args.fitted:
            raise invalid(flag, value, "only with --fitted (each family's joint fit)")
    args.draws = 20 if args.draws is None else args.draws
    args.seed = 0 if args.seed is None else args.seed
    if args.family and not args.fitted:
        raise invalid("--family", args.family[0], "chooses the families of --fitted; give --fitted too")
    if args.fitted:
        from rig.study.fitted_families import chosen_families

        families = chosen_families(args.family)  # a name this version lacks: refused before any work
    if args.identifiability or args.sensitivity or args.set or args.param or args.truth:
        from rig.cli.fig3_studies import run_fig3_studies

        return run_fig3_studies(args)
    from rig.study.reproduce import CONFIGS, MASS_RATIOS, OTHER_SCENES, VELOCITY_FACTORS, reproduce

    total = len(CONFIGS) + len(OTHER_SCENES) + len(CONFIGS) * len(VELOCITY_FACTORS) + len(MASS_RATIOS) + 1
    with progress_bar(args.quiet, total=total, desc=f"reproduce {args.study}", unit="step") as bar:
        def progress(what):
            bar.set_postfix_str(what[:40])
            bar.update()

        with writing_to(args.out):
            results = reproduce(args.study, args.out, progress)
    block = {"out": args.out, "table1": results["table1"], "summary": results["summary"]}
    if args.fitted:
        from rig.study.reproduce_fitted import DASHPOTS, reproduce_fitted

        steps = 3 * len(families) + len(DASHPOTS) + 3  # each family's fits and shots, the scan, steel, the kept set
        with progress_bar(args.quiet, total=steps, desc="fitted models", unit="step") as bar:
            def progress(what):
                bar.set_postfix_str(what[:40])
                bar.update()

            with writing_to(args.out):
                block["fitted"] = reproduce_fitted(args.out, progress, families, args.starts, args.global_search,
                                                   args.seed, lambda what: bar.set_postfix_str(what[:60]))
    if not args.json:
        print((Path(args.out) / "table1.md").read_text())
        if args.fitted:
            print((Path(args.out) / "fitted.md").read_text())
        print(f"wrote {folder_shown(args.out)}: table1.md, table1.csv, summary.md, results.json and the figures"
              + (", fitted.md, fitted.json" if args.fitted else ""))
    return block


def add_sweep(sub) -> None:
    """The parser of ``rig sweep``."""
    sw = command(sub, "sweep", "one shot per value of a scene key", cmd_sweep)
    sw.add_argument("scene")
    sw.add_argument("--vary", required=True, action="append", metavar="KEY=START:STOP:COUNT",
                    help="the one key to sweep, e.g. striker.velocity=0.3:1.5:7 (plain numbers in the key's SI unit)")
    sw.add_argument("--set", action="append", metavar="KEY=VALUE", help="other overrides")
    sw.add_argument("--seed", type=seed_arg, default=0, help="the sweep's seed (default 0)")
    sw.add_argument("--out", metavar="ARCHIVE.h5", help="append every shot to an archive")
    sw.add_argument("--quiet", action="store_true", help="no progress bar")
    allow_large(sw)


def add_reproduce(sub) -> None:
    """The parser of ``rig reproduce``."""
    rp = command(sub, "reproduce", "re-run a published study (daraio2006)", cmd_reproduce)
    rp.add_argument("study", choices=["daraio2006"], help="the published study to re-run")
    rp.add_argument("--out", required=True, metavar="DIR", help="folder for tables and figures")
    rp.add_argument("--fitted", action="store_true",
                    help="also fit the PTFE model to the published experiment (Table 1) and compare its shots")
    rp.add_argument("--family", action="append", metavar="NAME",
                    help="with --fitted: fit only this model family (repeat for more; default: every one)")
    rp.add_argument("--starts", type=starts_arg, default=1, metavar="N",
                    help="with --fitted: start each family's joint fit from N points (rig fit --starts); every "
                         "distinct optimum is in its row's \"optima\" (default 1)")
    global_search_arg(rp)
    rp.add_argument("--identifiability", action="store_true",
                    help="instead: fit each new contact parameter to noisy virtual Fig. 3 observations (20 data "
                         "sets each) and count the 95%% intervals that hold the truth (identifiability.json, .md)")
    rp.add_argument("--sensitivity", action="store_true",
                    help="instead: each Fig. 3 figure's d ln(figure)/d ln(p) and each key's window meeting every "
                         "Fig. 3 target, at the Fig. 3 parameter set or --set (sensitivity.json, .md)")
    rp.add_argument("--set", action="append", metavar="KEY=VALUE",
                    help="with --identifiability or --sensitivity: overrides of the Fig. 3 parameter set")
    rp.add_argument("--param", action="append", metavar="KEY=LO:HI",
                    help="with --identifiability: a key to find again (with --truth), instead of the five new ones")
    rp.add_argument("--truth", action="append", metavar="VALUE",
                    help="with --param: its truth, a quantity in the key's unit (one per --param, in order)")
    rp.add_argument("--draws", type=count_arg,
                    help="with --identifiability: data sets per key (default 20)")
    rp.add_argument("--seed", type=seed_arg, help="with --identifiability: the noise's seed; with --fitted "
                                                  "--global-search: its population's (default 0)")
    rp.add_argument("--allow-large", action="store_true",
                    help="with --identifiability: run even when its estimate passes a day")
    rp.add_argument("--quiet", action="store_true", help="no progress bar")
