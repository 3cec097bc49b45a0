"""`rig fit`: fit a scene's keys to measured points or to scope records."""
from __future__ import annotations

import sys
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from rig.fit.observations.objective import ObservationObjective
    from rig.fit.points import PointObjective
    from rig.fit.traces import TraceObjective

from rig.cli.common import command, count_arg, seed_arg


def _records(args, overrides: list, fitted: dict) -> tuple:
    """(the scope records to fit, each one's set-up or None): one shot's files (--records),
    or an archive's shots, each virtual one modelled with its own overrides
    (rig.fit.checks.archived_setups)."""
    from instruments.formats import read_record

    if args.records:
        from rig.fit.checks import check_distinct_files

        check_distinct_files("--records", args.records)
        return [read_record(args.records)], None
    from instruments.archive import Archive
    from rig.fit.checks import archived_setups

    arch = Archive(args.archive)
    ids = arch.ids() if args.shot is None else [args.shot]
    entries = [arch.read(i, with_truth=False) for i in ids]
    return [e.record for e in entries], archived_setups(args.archive, args.scene, overrides, set(fitted), entries)


def cmd_fit(args) -> dict:
    from rig.cli.common import folder_shown, scene_overrides, writing_to
    from rig.errors import RigError, invalid
    from rig.experiment import scene as scene_io
    from rig.fit.fitting import stderr_progress
    from rig.fit.parameters import POSITIVE_LAW_KEYS, parse_parameters
    from rig.fit.run import run_fit

    sources = [s for s in ("records", "archive", "points", "observations") if getattr(args, s)]
    if len(sources) != 1:
        raise RigError("no data to fit: give one of --records FILES, --archive A.h5, --points TABLE.csv or "
                       "--observations FILE.toml"
                       if not sources else f"give one kind of data, not {' and '.join('--' + s for s in sources)}")
    if args.shot is not None and not args.archive:
        raise invalid("--shot", args.shot, f"picks one shot of --archive A.h5, not of --{sources[0]}")
    if args.walkers is not None and not args.posterior:
        raise invalid("--walkers", args.walkers, "needs --posterior STEPS (it is the MCMC sampler's)")
    if args.seed is not None and not (args.posterior or args.global_search):
        raise invalid("--seed", args.seed,
                      "needs --posterior STEPS or --global-search GENERATIONS (the draws it seeds)")
    params = parse_parameters(args.param)
    if args.posterior:
        from rig.fit.posterior import check

        check(args.walkers, len(params))
    fitted = {t.split("=", 1)[0].strip(): f"--param {t}" for t in args.param}
    overrides = list(scene_overrides(args, fitted))
    for p in params:  # a fitted damping switches its contact law on, after --set
        laws = POSITIVE_LAW_KEYS.get(p.key, ())
        for item in overrides:
            key, _, value = item.partition("=")
            if laws and key.strip() == "chain.contact_law" and value.strip().lower() not in laws:
                raise invalid("--set", item, f"--param {p.key} belongs to the {' or '.join(laws)} law and "
                                             f"switches chain.contact_law to {laws[0]}; leave the --set out")
    scene_io.load(args.scene, overrides)  # the scene and its overrides, checked before any work
    points = None
    if args.points:
        from rig.fit.data import read_points

        points = read_points(args.points)
        columns = {item.split("=", 1)[0]: f"--points {args.points} (its column, row by row)"
                   for config in points.configs for item in config}
        both = sorted(set(fitted) & set(columns))
        if both:
            raise invalid("--param", both[0], f"{columns[both[0]]} already gives it: a fitted key cannot also be fixed")
        scene_overrides(args, columns)
    objective: ObservationObjective | PointObjective | TraceObjective
    if args.observations:
        from rig.fit.observations.objective import ObservationObjective
        from rig.fit.observations.reading import read_observations

        observations = read_observations(args.observations, args.scene)
        objective = ObservationObjective(args.scene, params, observations, overrides, args.observations)
    elif points is not None:  # --points
        from rig.fit.points import PointObjective

        objective = PointObjective(args.scene, params, points, overrides)
    else:
        from rig.fit.traces import TraceObjective

        records, setups = _records(args, overrides, fitted)
        objective = TraceObjective(args.scene, params, records, overrides, setups)
    progress = None if args.quiet else stderr_progress
    with writing_to(args.out):
        block = run_fit(args.scene, objective, args.out, progress, args.max_evaluations, args.posterior,
                        args.walkers, args.seed or 0, args.starts, args.global_search)
    if not args.json:
        for k, p in block["parameters"].items():
            unit = "" if p["unit"] == "1" else f" {p['unit']}"
            print(f"{k:28s} {p['estimate']:.6g} +- {p['std']:.2g}{unit}   95%: [{p['ci95'][0]:.6g}, "
                  f"{p['ci95'][1]:.6g}]{'  AT BOUND' if k in block['at_bound'] else ''}")
        goodness = ("chi2/dof undefined (no degrees of freedom)" if block["chi2_reduced"] is None else
                    f"chi2/dof {block['chi2_reduced']:.3f} (p = {block['p_value']:.3g})")
        print(f"{goodness}, BIC {block['bic']:.2f}, residual rms {block['residual_rms_relative']:.2%}")
        gs = block.get("global_search")
        if gs:
            print(f"global search: {gs['generations']} generations of {gs['population']} members (seed {gs['seed']}), "
                  f"{gs['candidates']} candidates, best chi2 {gs['best_chi2']:.6g}")
        for o in block.get("optima", [])[1:]:
            print("another optimum: " + ", ".join(f"{k} {v:.6g}{'' if o['unit'][k] == '1' else ' ' + o['unit'][k]}"
                                                   for k, v in o["estimate"].items())
                  + f", chi2 {o['chi2']:.6g} ({'converged' if o['converged'] else 'not converged'})")
        for line in block["warnings"]:
            print(f"warning: {line}")
        for pair in block["highly_correlated"]:
            print(f"warning: {pair['keys'][0]} and {pair['keys'][1]} cannot be told apart "
                  f"(correlation {pair['correlation']:+.3f}); their intervals are wide for that reason")
        num = block["numerics"]
        est = ", ".join("none" if e is None else f"{e:.2g}" for e in (num["estimate_at_start"], num["estimate_at_fit"]))
        print(f"numerics: the model's error estimate {est} (start, result) against the accuracy "
              f"{num['accuracy']:.2g} (relative force error)")
        if not num["within_accuracy"] and num["step_at_floor"]:
            print("warning: the model's error estimate exceeds the scene's accuracy setting even at the "
                  "finest step a fit takes (1/16 of the a-priori rule's): the record's error does not fall "
                  "with the step (a contact that closes or not by a hair); the intervals do not include it")
        elif not num["within_accuracy"]:
            print("warning: the model's error estimate exceeds the scene's accuracy setting; "
                  "set a smaller solver.accuracy (--set) and fit again")
        post = block.get("posterior")
        if post:
            print(f"posterior ({post['walkers']} walkers x {post['steps']} steps, acceptance "
                  f"{post['acceptance_fraction']:.2f}, seed {post['seed']}):")
            for k, p in post["parameters"].items():
                unit = "" if p["unit"] == "1" else f" {p['unit']}"
                print(f"  {k:26s} median {p['median']:.6g}{unit}   68%: [{p['ci68'][0]:.6g}, {p['ci68'][1]:.6g}]"
                      f"   95%: [{p['ci95'][0]:.6g}, {p['ci95'][1]:.6g}]")
            if not post["long_enough"]:
                kept = post["steps"] - post["burn"]
                if None in post["autocorr_steps"]:
                    why = "too few to estimate the autocorrelation times (50 at least)"
                else:
                    taus = ", ".join(f"{t:.1f}" for t in post["autocorr_steps"])
                    why = f"fewer than 50 autocorrelation times ({taus} steps)"
                print(f"  {kept} steps kept, {why}: the same command with more steps goes on with this chain")
        print(f"wrote {folder_shown(args.out)}: fit.json, residuals.csv, fit.png" + (", posterior.png" if post else "")
              + (f", fitted.toml (rig shot {block['fitted_scene']})" if block["fitted_scene"] else ""))
    if not block["converged"]:
        print(f"rig fit: error: the fit did not converge ({block['message']}); no fitted scene written",
              file=sys.stderr)
        args.exit_code = 1
    elif block["unusable"]:
        print(f"rig fit: error: the fit converged, but {block['unusable']}; no fitted scene written",
              file=sys.stderr)
        args.exit_code = 1
    return block


def starts_arg(text: str) -> int:
    """--starts: a whole number of starts 1..100."""
    from rig.cli.common import whole_number

    return whole_number(text, 1, 100, "a whole number of starts from 1 to 100")


def generations_arg(text: str) -> int:
    """--global-search: a whole number of generations 1..1000."""
    from rig.cli.common import whole_number

    return whole_number(text, 1, 1000, "a whole number of generations from 1 to 1000")


def global_search_arg(parser) -> None:
    """--global-search GENERATIONS (rig fit, rig reproduce --fitted)."""
    parser.add_argument("--global-search", type=generations_arg, default=0, metavar="GENERATIONS",
                        help="first search the bounds globally: differential evolution for at most GENERATIONS "
                             "generations (10 members per fitted key, drawn from --seed), the local fits then "
                             "starting from its best members too; every candidate cached in the evaluations "
                             "folder, so the same command run again resumes")


def add_fit(sub) -> None:
    """The parser of ``rig fit``."""
    fi = command(sub, "fit", "fit scene keys to measured points, scope records or observations", cmd_fit)
    fi.add_argument("scene", help="the model: a scene file, or a published scene's name")
    fi.add_argument("--param", action="append", metavar="KEY=LO:HI",
                    help="a scene key to fit with its bounds in units, e.g. 'chain.youngs_modulus=0.4 GPa:2 GPa' "
                         "(a dimensionless key: plain numbers, e.g. chain.contact_exponent=1.2:2.4)")
    fi.add_argument("--records", nargs="+", metavar="FILE", help="one shot's scope files (ISF, CSV, WFM)")
    fi.add_argument("--archive", metavar="A.h5", help="an archive: every shot (or --shot N)")
    fi.add_argument("--shot", type=count_arg, help="with --archive: one shot")
    fi.add_argument("--points", metavar="TABLE.csv",
                    help="measured points: columns 'F_d [N]', 'F_d_sd [N]', 'V_s [m/s]', 'V_s_sd [m/s]' "
                         "and scene keys per row, e.g. 'magnet.force [N]'")
    fi.add_argument("--observations", metavar="FILE.toml",
                    help="observed figures of shots ([[observation]] kind, value, sd, scene, set, gauge: a speed, "
                         "a gauge reading's peak, fwhm, duration, pulses, wall_peak, tail, ratio)")
    fi.add_argument("--set", action="append", metavar="KEY=VALUE", help="fixed overrides of the scene")
    fi.add_argument("--out", required=True, metavar="DIR",
                    help="folder for fit.json, residuals.csv, fit.png, fitted.toml; its evaluations/ resume a fit")
    fi.add_argument("--max-evaluations", type=count_arg, default=400, help="the fit's budget (default 400)")
    fi.add_argument("--starts", type=starts_arg, default=1, metavar="N",
                    help="start the fit from N points (the scene's values where it sets them, else the bounds' middle; "
                         "then points spread over the bounds) and "
                         "keep the best: a narrow window or a second minimum is found; every distinct optimum is in "
                         "fit.json's \"optima\" (default 1)")
    global_search_arg(fi)
    fi.add_argument("--posterior", type=count_arg, default=0, metavar="STEPS",
                    help="then sample the posterior by MCMC for STEPS steps (needs the extra: "
                         "pip install 'sonic-rig[posterior]'); resumes in DIR/posterior.h5")
    fi.add_argument("--walkers", type=count_arg, help="with --posterior: walkers (default 4 per parameter, at least 8)")
    fi.add_argument("--seed", type=seed_arg, help="with --posterior: the walkers' seed; with --global-search: its "
                                                  "population's (default 0)")
    fi.add_argument("--quiet", action="store_true", help="no progress lines")
