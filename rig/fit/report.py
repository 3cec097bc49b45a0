"""What a fit leaves in its folder: fit.json (the --json block and more), residuals.csv,
fit.png (the data against the fitted model) and, only for a fit that converged,
fitted.toml: the scene with the fitted values, which `rig shot` fires."""
from __future__ import annotations

import csv
from pathlib import Path

import numpy as np

from instruments.files import atomic_write
from rig.experiment import scene as scene_io
from rig.fit.checks import result_warnings, unusable
from rig.fit.fitting import FitResult
from rig.fit.observations.objective import NO_FIGURE, ObservationObjective
from rig.fit.points import PointObjective


def summary(result: FitResult, objective, fitted_scene) -> dict:
    """The --json block: {"parameters": {KEY: {"estimate", "std", "ci95", "unit"}}, "correlation",
    "residual_rms_relative", "converged", "plausible", "interval_scale", "warnings",
    "fitted_scene", "numerics", ...}. converged: the optimiser's; plausible: the chi2's
    verdict on the model (None without degrees of freedom); interval_scale: sqrt(chi2/dof)
    where above 1, the factor already in the sds; undetermined: keys whose 95% interval
    passes both their bounds; unusable: why a converged fit writes no fitted scene (None where it does);
    warnings: rig.fit.checks.result_warnings; observations (an observations fit): each
    observation's observed value, sd, model figure (None where it has none) and residual.
    chi2_reduced and p_value are None where undefined (no degrees of freedom)."""
    block = {
        "parameters": {k: {"estimate": float(e), "std": float(s), "ci95": [float(lo), float(hi)], "unit": u}
                       for k, u, e, s, (lo, hi) in zip(result.keys, result.units, result.estimate, result.std,
                                                        result.ci95)},
        "correlation": np.round(result.correlation, 6).tolist(),
        "highly_correlated": [{"keys": [a, b], "correlation": rho} for a, b, rho in result.correlated_pairs()],
        "residual_rms_relative": objective.relative_rms(result.model, result.eta),
        "converged": result.converged,
        "message": result.message,
        "at_bound": list(result.at_bound),
        "chi2": result.chi2, "dof": result.dof, "chi2_reduced": _finite_or_none(result.chi2_reduced),
        "p_value": _finite_or_none(result.p_value), "bic": result.bic,
        "plausible": result.plausible, "interval_scale": result.interval_scale,
        "undetermined": list(result.undetermined), "unusable": unusable(result) or None,
        "warnings": result_warnings(result, objective.params),
        "evaluations": result.evaluations, "evaluations_replayed": result.replayed,
        "nuisance": result.nuisance,
        "fitted_scene": None if fitted_scene is None else str(fitted_scene),
        "numerics": objective.numerics(result.estimate),
    }
    if isinstance(objective, ObservationObjective):
        block["observations"] = objective.figures(result.model, result.residuals)
        block["warnings"] += [f"{o['observation']}: the fitted model gives no {o['kind']} (a shot refused or blown "
                              f"up, or no pulse to measure); its residual counts as {NO_FIGURE:g} sd"
                              for o in block["observations"] if o["model"] is None]
    return block


def _finite_or_none(x: float):
    return float(x) if np.isfinite(x) else None


def fitted_scene_text(scene: str, overrides: list, result: FitResult) -> str:
    """The scene's TOML with the overrides and the fitted values set (each with its unit)."""
    import tomli_w

    _, raw = scene_io.read_raw(scene)
    name = raw["scene"]["name"]
    for item in list(overrides) + [f"{k}={float(v)!r}" for k, v in zip(result.keys, result.estimate)]:
        scene_io.apply_override(raw, item)
    raw["scene"]["name"] = f"{name}_fitted"
    head = (f"# {name} fitted by `rig fit`: "
            + ", ".join(f"{k} = {e:.6g} +- {s:.2g}" + ("" if u == "1" else f" {u}")
                        for k, u, e, s in zip(result.keys, result.units, result.estimate, result.std))
            + "\n")
    return head + tomli_w.dumps(raw)


def write_residuals(path: Path, objective, result: FitResult):
    atomic_write(path, lambda tmp: _residuals(tmp, objective, result))


def _residuals(path, objective, result: FitResult):
    model = result.model
    with open(path, "w", newline="") as fh:
        wr = csv.writer(fh)
        if isinstance(objective, ObservationObjective):
            wr.writerow(objective.ROW_HEADER)
            wr.writerows(objective.rows(model, result.residuals))
        elif isinstance(objective, PointObjective):
            p = objective.points
            V, _ = objective.model_speeds(model)
            wr.writerow(["F_d [N]", "V_s [m/s]", "V_s model [m/s]", "relative (model / measured - 1)",
                         "normalised (model - measured) / effective sd", "configuration"])
            for i in range(p.n):
                wr.writerow([p.force[i], p.speed[i], V[i], V[i] / p.speed[i] - 1, result.residuals[i],
                             " ".join(p.configs[i])])
        else:
            wr.writerow(["record", "channel", "samples", "rms residual [V]", "noise sd [V]", "chi2 per sample"])
            k = 0
            for c in objective.channels:
                r = result.residuals[k:k + c.t.size]
                k += c.t.size
                wr.writerow([c.record, c.name, c.t.size, float(np.sqrt(np.mean(r ** 2))) * c.sd, c.sd,
                             float(np.mean(r ** 2))])


def draw(path: Path, objective, result: FitResult):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from rig.viz.figures import save

    model = result.model
    if isinstance(objective, ObservationObjective):
        fig, ax = plt.subplots(figsize=(6.4, 1.2 + 0.35 * len(objective.observations)))
        y = np.arange(len(objective.observations))[::-1]
        ax.axvspan(-1.0, 1.0, color="0.85", label="observed +- 1 sd")
        ax.plot(np.clip(result.residuals, -10.0, 10.0), y, "D", color="C3", label="fitted model")
        ax.set_yticks(y, [" ".join(x for x in (o.kind, o.of, o.gauge, o.shot.scene) if x)
                          for o in objective.observations], fontsize=7)
        ax.set_xlabel("(model - observed) / sd  (clipped at +-10)")
        ax.legend(fontsize=7)
    elif isinstance(objective, PointObjective):
        p = objective.points
        fig, ax = plt.subplots(figsize=(6.4, 4.6))
        for c, (config, curve) in enumerate(zip(objective.configs, model)):
            rows = objective.config_of == c
            label = " ".join(config) or "data"
            ax.errorbar(p.force[rows], p.speed[rows], xerr=p.force_sd[rows], yerr=p.speed_sd[rows], fmt="o",
                        ms=5, capsize=2, label=f"measured {label}", color=f"C{c}")
            ok = np.isfinite(curve.force) & np.isfinite(curve.speed)
            ax.plot(curve.force[ok], curve.speed[ok], "-", color=f"C{c}", label=f"fitted model {label}")
        ax.set_xscale("log")
        ax.legend(fontsize=7)
        ax.set_xlabel("dynamic contact force F_d (N)")
        ax.set_ylabel("leading pulse speed V_s (m/s)")
    else:
        traces = objective.traces(model, result.eta)
        fig, axes = plt.subplots(len(objective.channels), 1, figsize=(7.0, 2.2 * len(objective.channels)),
                                 sharex=True, squeeze=False)
        for ax, c, m in zip(axes[:, 0], objective.channels, traces):
            ax.plot(c.t * 1e3, c.y, ".", ms=1.5, color="0.5", label=f"record {c.record} {c.name}")
            if m is not None:
                ax.plot(c.t * 1e3, m, "-", lw=1.0, color="C3", label="fitted model")
            ax.set_ylabel("V")
            ax.legend(fontsize=7, loc="upper right")
        ax = axes[-1, 0]
        ax.set_xlabel("time from the trigger (ms)")
    title = ", ".join(f"{k.split('.')[-1]} = {e:.6g} ± {s:.2g}" + ("" if u == "1" else f" {u}")
                      for k, u, e, s in zip(result.keys, result.units, result.estimate, result.std))
    fig.suptitle(title, fontsize=9)
    fig.tight_layout()
    save(fig, path, dpi=130)
    plt.close(fig)
