"""`rig reproduce daraio2006 --identifiability | --sensitivity`: the Fig. 3 studies
(rig.study.identifiability, rig.study.sensitivity), run instead of the published study."""
from __future__ import annotations

import json
import types
from pathlib import Path

from rig.cli.common import check_export_folder, folder_shown, progress_bar, scene_overrides, writing_to
from rig.errors import RigError, invalid


def parameter_set(args) -> tuple:
    """The Fig. 3 parameter set with the command's --set items (a key given there replaces the
    set's), each checked by loading both shots' scenes."""
    from rig.experiment.scene import load
    from rig.study import fig3

    given = scene_overrides(args)
    merged = replaced(fig3.PARAMETER_SET, given)
    for scene in (fig3.GRAVITY, fig3.MAGNETIC):
        load(scene, list(merged))
    return merged


SAME_QUANTITY = ({"chain.yield_force", "chain.yield_pressure"},)
"""Keys that set one quantity in two ways (the contacts' yield: a force, converted, or a
pressure): a --set item of one replaces the parameter set's other."""


def replaced(overrides: tuple, given: tuple) -> tuple:
    """``overrides`` less the items whose key ``given`` sets (itself, or another key of the
    same quantity, SAME_QUANTITY), then ``given``."""
    keys = {item.split("=", 1)[0].strip() for item in given}
    for group in SAME_QUANTITY:
        if keys & group:
            keys |= group
    return tuple(o for o in overrides if o.split("=", 1)[0].strip() not in keys) + tuple(given)


def questions(args, overrides: tuple) -> tuple:
    """The identifiability questions: the five new keys' (rig.study.identifiability.QUESTIONS,
    each with the --set items over its own fixed keys) or the --param/--truth pairs'."""
    from rig.fit.parameters import parse_parameter
    from rig.study.identifiability import QUESTIONS, Question, truth_value

    params, truths = args.param or [], args.truth or []
    if len(params) != len(truths):
        raise invalid("--truth", truths, f"one truth per --param ({len(params)} --param, {len(truths)} --truth)")
    if not params:
        given = scene_overrides(args)
        return tuple(Question(q.bounds, q.truth, replaced(q.overrides, given), q.why) for q in QUESTIONS)
    out = []
    for text, truth in zip(params, truths):
        truth_value(parse_parameter(text), truth)  # a bad key, bounds or truth: one line before any solve
        out.append(Question(text, truth, overrides, "given on the command line"))
    return tuple(out)


SECONDS_PER_FIT = 5.7  # an identifiability fit, one core (the default 5 keys x 20 draws: 9-10 min)
MOST_SECONDS = 86400.0  # beyond a day's estimate a study waits for --allow-large


def _announce(fits: int, draws: int, allowed: bool) -> None:
    """Say what the identifiability study will take before it starts (stderr); refuse past
    MOST_SECONDS without --allow-large."""
    import sys

    seconds = fits * SECONDS_PER_FIT
    span = f"{seconds / 3600:.3g} h" if seconds >= 3600 else f"{seconds / 60:.3g} min"
    said = f"{fits} fits at about {SECONDS_PER_FIT:g} s each: about {span}"
    if seconds > MOST_SECONDS and not allowed:
        raise invalid("--draws", draws, f"the identifiability study would take {said} ({seconds / 86400:.3g} days), "
                                        f"beyond a day; give fewer --draws, or add --allow-large")
    print(f"identifiability: {said}", file=sys.stderr, flush=True)


def run_fig3_studies(args) -> dict:
    if not (args.identifiability or args.sensitivity):
        flag = "--set" if args.set else "--param" if args.param else "--truth"
        raise invalid(flag, args.set or args.param or args.truth, "only with --identifiability or --sensitivity")
    if args.fitted:
        raise invalid("--fitted", True, "not with --identifiability or --sensitivity (they run instead of the study)")
    if not args.identifiability and (args.param or args.truth):
        raise invalid("--param", args.param or args.truth, "only with --identifiability")
    check_export_folder(args.out, "--out")
    overrides = parameter_set(args)
    plans = []
    if args.identifiability:
        plans.append(("identifiability", questions(args, overrides)))
    if args.sensitivity:
        plans.append(("sensitivity", overrides))
    block, out = {"out": args.out}, Path(args.out)
    study: types.ModuleType  # identifiability or sensitivity: each has study() and table()
    for name, plan in plans:
        if name == "identifiability":
            from rig.study import identifiability as study

            total = len(plan) * args.draws
            _announce(total, args.draws, args.allow_large)
            with progress_bar(args.quiet, total=total, desc="identifiability", unit="fit") as bar:
                def progress(what, bar=bar):
                    bar.set_postfix_str(what[:60])
                    bar.update()

                result = study.study(plan, args.draws, args.seed, progress)
        else:
            from rig.study import sensitivity as study

            with progress_bar(args.quiet, desc="sensitivity", unit="step") as bar:
                def progress(what, bar=bar):
                    bar.set_postfix_str(what[:60])
                    bar.update()

                result = study.study(plan, progress)
        text = study.table(result)
        try:
            with writing_to(out):
                out.mkdir(parents=True, exist_ok=True)
                (out / f"{name}.json").write_text(json.dumps(result, indent=1, allow_nan=False) + "\n")
                (out / f"{name}.md").write_text(text)
        except ValueError as exc:  # a nan that json refuses: a figure the study should have named
            raise RigError(f"{name}.json: {exc}") from None
        block[name] = result
        if not args.json:
            print(text)
    if not args.json:
        print(f"wrote {folder_shown(args.out)}: " + ", ".join(f"{n}.md, {n}.json" for n, _ in plans))
    return block
