"""`rig fit`: a scene's keys fitted to measured points or scope records (rig.fit)."""
from __future__ import annotations

import json
from pathlib import Path

from instruments.errors import InstrumentError
from instruments.files import atomic_write, folder_lock, left_as_found, write_text
from rig.errors import Interrupted, RigError
from rig.experiment import scene as scene_io
from rig.fit import report
from rig.fit.globalsearch import optima_block, searched_fit

LOCK = "fit.lock"  # held in the --out folder while a fit writes it: a second fit into it is refused


def run_fit(scene: str, objective, out, progress=None, max_evaluations: int = 400, posterior_steps: int = 0,
            walkers: int | None = None, seed: int = 0, starts: int = 1, generations: int = 0) -> dict:
    """Fit ``objective`` and write the folder ``out`` (rig.fit.report); returns the JSON
    block. Evaluations are cached in out/evaluations/: the same command run again after an
    interruption replays them instead of solving them again. A fit that did not converge
    writes everything but the fitted scene, and so does one whose model cannot describe the
    data or leaves a parameter undetermined (FitResult.usable); a refused one (RigError)
    leaves the folder as it was: what this run added is removed (the folder too where
    this run created it), what was there before is kept. An I/O failure (a full disk) or an
    interruption keeps what was cached before it (evaluations, the posterior's chain) and
    removes only the folders it left empty. posterior_steps > 0: a converged fit's posterior
    is then sampled (rig.fit.posterior: ``walkers``, default 4 per parameter and at least
    8, drawn from ``seed``) into the block's "posterior" and out/posterior.png. The folder
    is held (LOCK) while the fit runs: a second fit into it is refused in one line, naming
    the run that holds it, rather than the two overwriting each other. ``starts`` > 1: the fit
    starts from that many points (rig.fit.fitting.multistart), keeps the best and lists every
    distinct optimum in the block's "optima"; ``generations`` > 0: a global search first
    (rig.fit.globalsearch, drawn from ``seed``; the block's "global_search"), the local fits
    then starting from its best members too."""
    kept = (OSError, Interrupted)  # a full disk, Ctrl-C: what was cached stays, for the same command to resume from
    with left_as_found(out, (RigError, OSError, InstrumentError), keep=lambda exc: isinstance(exc, kept)), \
            folder_lock(out, LOCK, "wait for it to end, or give another --out", keep=lambda: False):
        return _fit_into(scene, objective, Path(out), progress, max_evaluations, posterior_steps, walkers, seed,
                         starts, generations)


def _fit_into(scene, objective, out: Path, progress, max_evaluations, posterior_steps, walkers, seed,
              starts, generations) -> dict:
    """run_fit's work, writing into ``out``."""
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise RigError(f"--out {out}: cannot create ({exc.strerror})") from None
    result, optima, found = searched_fit(objective, starts, generations, seed, out / "evaluations", max_evaluations,
                                         progress)
    fitted = None
    stale = out / "fitted.toml"
    if stale.exists():
        stale.unlink()  # a fitted scene from an earlier fit must not outlive a failed one
    if result.usable:
        text = report.fitted_scene_text(scene, objective.overrides, result)

        def write(tmp):
            Path(tmp).write_text(text)
            scene_io.load(tmp)  # the written scene must load as it is

        fitted = atomic_write(stale, write)
    block = report.summary(result, objective, fitted)
    if starts > 1 or found is not None:
        block["optima"] = optima_block(result, optima)
    if found is not None:
        block["global_search"] = found.as_dict(result.keys)
    if posterior_steps and result.converged:
        from rig.fit import posterior

        post = posterior.sample(objective, result, out, walkers or max(8, 4 * len(result.keys)), posterior_steps,
                                seed, progress)
        block["posterior"] = post.as_dict()
        posterior.draw(out / "posterior.png", post)
    report.write_residuals(out / "residuals.csv", objective, result)
    report.draw(out / "fit.png", objective, result)
    write_text(out / "fit.json", json.dumps(block, indent=1, default=float))
    return block
