"""`rig reproduce daraio2006 --fitted`: the PTFE model fitted to the published experiment.

1. Model selection on Table 1's ten experimental points (errors in variables, rig.fit.points):
   the modulus alone (the published Hertz law), modulus and contact exponent, and those with
   a dashpot in the contacts. Each earns its place by the leave-one-out cross-validation of
   the models with one and two parameters (each point predicted by the model fitted to the
   other nine; the model kept is the one that predicts the held-out points best, lowest
   summed chi2) and by BIC: the three-parameter model, whose ten fits would triple the
   command's time, is not cross-validated and would be kept only with a lower BIC than
   both.
2. Prediction: modulus and exponent fitted to the five gravity-only points, then compared
   with the five magnetic ones.
3. The fitted model's shots at the published 0.89 m/s, with and without the magnet: speed,
   duration, amplitude ratio, wall force and tail, beside the published experiment.
4. Dissipation: the dashpot that would bring the gravity-only shot to the published 129 m/s,
   and what it does to Table 1.
5. Steel-21: the modulus fitted to the two published speeds (580 and 688 m/s at 0.44 m/s).
"""
from __future__ import annotations

import json
import math
from importlib import resources
from pathlib import Path

import numpy as np

from instruments.files import write_text
from rig.experiment.shot import Rig
from rig.fit.data import read_points
from rig.fit.evaluate import calibrate, curves, solve_rigs
from rig.fit.fitting import fit
from rig.fit.parameters import parse_parameters
from rig.fit.points import PointObjective

E_BOUNDS = "chain.youngs_modulus=0.2 GPa:4 GPa"
N_BOUNDS = "chain.contact_exponent=1.05:2.6"
MU_BOUNDS = "chain.contact_damping=0.001 kg/s:3 kg/s"
MODELS = {"hertz": [E_BOUNDS], "power law": [E_BOUNDS, N_BOUNDS],
          "power law + dashpot": [E_BOUNDS, N_BOUNDS, MU_BOUNDS]}
CROSS_VALIDATED = ("hertz", "power law")
PUBLISHED = {"gravity_speed": 129.0, "gravity_duration_s": 170e-6, "magnetic_speed": 222.0, "amplitude_ratio": 2.0,
             "steel_gravity_speed": 580.0, "steel_magnetic_speed": 688.0}
DASHPOTS = (0.0, 0.05, 0.1, 0.2, 0.4, 0.8, 1.6)  # kg/s


def table1_points():
    path = resources.files("rig") / "scenes" / "daraio2006" / "table1_experiment.csv"
    with resources.as_file(path) as p:
        return read_points(p)


def _fit(points, bounds, tell):
    obj = PointObjective("ptfe52_gravity", parse_parameters(bounds), points)
    r = fit(obj)
    tell(f"fitted {', '.join(b.split('=')[0] for b in bounds)}")
    return obj, r, r.model, obj.relative_residuals(r.model)


def leave_one_out(scene: str, points, bounds, tell) -> dict:
    """Each point predicted by the model fitted to the others: the sum of the held-out
    points' squared normalised residuals (errors in variables, as the fit's chi2) and the
    RMS of their relative speed residuals."""
    r2, rel = np.empty(points.n), np.empty(points.n)
    for i in range(points.n):
        rest = points.subset([k for k in range(points.n) if k != i])
        r = fit(PointObjective(scene, parse_parameters(bounds), rest))
        held = PointObjective(scene, parse_parameters(bounds), points.subset([i]))
        (model,) = held.evaluate([r.estimate])
        r2[i] = float(held.residuals(model, np.zeros(0))[0]) ** 2
        rel[i] = float(held.relative_residuals(model)[0])
    tell(f"cross-validated {', '.join(b.split('=')[0] for b in bounds)}")
    return {"loo_chi2": float(r2.sum()), "loo_rms_relative": float(np.sqrt(np.mean(rel ** 2))),
            "loo_relative_residuals": rel.tolist()}


def _block(r, rel) -> dict:
    return {"parameters": {k: {"estimate": float(e), "std": float(s), "ci95": [float(a), float(b)]}
                           for k, e, s, (a, b) in zip(r.keys, r.estimate, r.std, r.ci95)},
            "chi2": r.chi2, "dof": r.dof, "bic": r.bic, "converged": r.converged, "at_bound": list(r.at_bound),
            "rms_relative": float(np.sqrt(np.mean(rel ** 2))), "max_relative": float(np.max(np.abs(rel))),
            "relative_residuals": rel.tolist()}


def fitted_shots(overrides: list) -> dict:
    """The fitted model's published shots at 0.89 m/s: gravity only and with 2.38 N, their
    whole records held to the scenes' accuracy (the accuracy control of a fit's pilot)."""
    rigs = {name: Rig.from_scene(name, overrides) for name in ("ptfe52_gravity", "ptfe52_magnetic")}
    solve_rigs(list(rigs.values()), calibrate(list(rigs.values())))
    out = {}
    for name, rig in rigs.items():
        t = rig.truth_analysis()
        w = rig.truth().wall_force
        out[name] = {"speed_m_per_s": t.speed_m_per_s, "amplitude_N": t.amplitude_N, "duration_s": t.duration_s,
                     "base_duration_s": t.base_duration_s, "pulses": t.pulses, "wall_peak_N": float(np.max(w) - w[0]),
                     "dissipated_energy_J": rig.solution().stats.dissipated_energy_J,
                     "error_estimate": rig.solution().stats.error_estimate}
    return out


def reproduce_fitted(out, progress=None) -> dict:
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    tell = progress or (lambda *a: None)
    pts = table1_points()
    fits = {name: _fit(pts, bounds, tell) for name, bounds in MODELS.items()}
    cv = {name: leave_one_out("ptfe52_gravity", pts, MODELS[name], tell) for name in CROSS_VALIDATED}
    best = min(cv, key=lambda k: cv[k]["loo_chi2"])
    by_bic = min(fits, key=lambda k: fits[k][1].bic)
    if by_bic not in cv:
        best = by_bic
    _, r_best, _, rel_best = fits[best]
    gravity = np.array([c == ("magnet.force=0.0",) for c in pts.configs])
    g_obj, g_r, _, _ = _fit(pts.subset(np.flatnonzero(gravity)), MODELS["power law"], tell)
    m_obj = PointObjective("ptfe52_gravity", g_obj.params, pts.subset(np.flatnonzero(~gravity)))
    (m_model,) = m_obj.evaluate([g_r.estimate])
    predicted = m_obj.relative_residuals(m_model)
    pl = fits["power law"][1]
    law = [f"{k}={float(v)!r}" for k, v in zip(pl.keys, pl.estimate)]
    shots = fitted_shots(law)
    tell("fitted shots")
    scan = []
    for mu in DASHPOTS:
        extra = [] if mu == 0 else ["chain.contact_law=dashpot", f"chain.contact_damping={mu!r}"]
        s = fitted_shots(law + extra)
        obj = PointObjective("ptfe52_gravity", (), pts, law + extra)
        (model,) = obj.evaluate([np.zeros(0)])
        rel = obj.relative_residuals(model)
        scan.append({"contact_damping_kg_per_s": mu, "table1_rms_relative": float(np.sqrt(np.nanmean(rel ** 2))),
                     "gravity_speed_m_per_s": s["ptfe52_gravity"]["speed_m_per_s"],
                     "gravity_duration_s": s["ptfe52_gravity"]["duration_s"],
                     "gravity_base_duration_s": s["ptfe52_gravity"]["base_duration_s"],
                     "magnetic_speed_m_per_s": s["ptfe52_magnetic"]["speed_m_per_s"],
                     "amplitude_ratio": _ratio(s)})
        tell(f"dashpot {mu:g} kg/s")
    steel = _steel(tell)
    g, m = shots["ptfe52_gravity"], shots["ptfe52_magnetic"]
    fitted = {
        "model": best,
        "table1_rms_relative": float(np.sqrt(np.mean(rel_best ** 2))),
        "table1_max_relative": float(np.max(np.abs(rel_best))),
        "gravity_fit_predicts_magnetic_rms_relative": float(np.sqrt(np.mean(predicted ** 2))),
        "ptfe52_gravity_speed_m_per_s": g["speed_m_per_s"],
        "ptfe52_magnetic_speed_m_per_s": m["speed_m_per_s"],
        "ptfe52_gravity_duration_s": g["duration_s"],
        "ptfe52_gravity_base_duration_s": g["base_duration_s"],
        "amplitude_ratio_magnetic_to_gravity": _ratio(shots),
        "wall_peak_gravity_N": g["wall_peak_N"], "wall_peak_magnetic_N": m["wall_peak_N"],
        "pulses_gravity": g["pulses"], "pulses_magnetic": m["pulses"],
        "parameters": {k: {"estimate": float(e), "std": float(s), "ci95": [float(a), float(b)]}
                       for k, e, s, (a, b) in zip(r_best.keys, r_best.estimate, r_best.std, r_best.ci95)},
        "models": {name: {**_block(f[1], f[3]), **cv.get(name, {})} for name, f in fits.items()},
        "gravity_only_fit": {k: {"estimate": float(e), "std": float(s)} for k, e, s in zip(g_r.keys, g_r.estimate,
                                                                                           g_r.std)},
        "power_law_shots": shots,
        "dashpot_scan": scan,
        "steel": steel,
        "published": PUBLISHED,
    }
    write_text(out / "fitted.json", json.dumps(fitted, indent=1, default=float))
    write_text(out / "fitted.md", _markdown(fitted))
    return fitted


def _ratio(shots: dict) -> float:
    a, b = shots["ptfe52_magnetic"]["amplitude_N"], shots["ptfe52_gravity"]["amplitude_N"]
    return float(a / b) if a and b else math.nan


def _steel(tell) -> dict:
    """Steel-21's modulus from its two published speeds at 0.44 m/s (10% each): a 1-D
    weighted least squares over a grid of moduli, refined by parabola."""
    grid = np.linspace(120e9, 260e9, 15)
    scenes = ("steel21_gravity", "steel21_magnetic")
    target = np.array([PUBLISHED["steel_gravity_speed"], PUBLISHED["steel_magnetic_speed"]])
    moduli = [[f"chain.youngs_modulus={float(E)!r}"] for E in grid]
    speeds = np.array([[c.speed[0] for c in curves(s, moduli, [0.44])] for s in scenes]).T
    chi2 = np.sum(((speeds - target) / (0.1 * target)) ** 2, axis=1)
    k = int(np.clip(np.nanargmin(chi2), 1, grid.size - 2))
    a, b, c = np.polyfit(grid[k - 1:k + 2], chi2[k - 1:k + 2], 2)
    E = float(-b / (2 * a)) if a > 0 else float(grid[k])
    fitted = [c.speed[0] for s in scenes for c in curves(s, [[f"chain.youngs_modulus={E!r}"]], [0.44])]
    tell("steel")
    return {"youngs_modulus_Pa": E, "youngs_modulus_std_Pa": float(math.sqrt(2 / a)) if a > 0 else math.nan,
            "gravity_speed_m_per_s": fitted[0], "magnetic_speed_m_per_s": fitted[1],
            "published_modulus_Pa": Rig.from_scene("steel21_gravity").chain.beads[-1].material.E}


def _markdown(f: dict) -> str:
    p = f["published"]
    lines = ["# Daraio 2006, fitted to the experiment", "",
             "| model | parameters | chi2 / dof | BIC | Table 1 RMS | worst | leave-one-out chi2 | leave-one-out RMS |",
             "|---|---|---|---|---|---|---|---|"]
    for name, b in f["models"].items():
        pars = ", ".join(f"{k.split('.')[-1]} {v['estimate']:.4g} ± {v['std']:.2g}" for k, v in b["parameters"].items())
        loo = (f"{b['loo_chi2']:.2f} | {b['loo_rms_relative']:.1%}" if "loo_chi2" in b else "not computed | -")
        lines.append(f"| {name} | {pars} | {b['chi2']:.2f} / {b['dof']} | {b['bic']:.2f} | "
                     f"{b['rms_relative']:.1%} | {b['max_relative']:.1%} | {loo} |")
    lines += ["", f"Model kept (best leave-one-out prediction; BIC for a model not cross-validated): "
              f"**{f['model']}**.",
              "Gravity-only fit predicts the magnetic points to "
              f"{f['gravity_fit_predicts_magnetic_rms_relative']:.1%} RMS.",
              "", "| observation | published experiment | fitted power law |", "|---|---|---|",
              f"| speed, gravity only, 0.89 m/s | {p['gravity_speed']:.0f} m/s | "
              f"{f['ptfe52_gravity_speed_m_per_s']:.0f} m/s |",
              f"| duration, gravity only | 170 us | {f['ptfe52_gravity_duration_s'] * 1e6:.0f} us (FWHM), "
              f"{(f['ptfe52_gravity_base_duration_s'] or math.nan) * 1e6:.0f} us (base) |",
              f"| speed with 2.38 N | {p['magnetic_speed']:.0f} m/s | {f['ptfe52_magnetic_speed_m_per_s']:.0f} m/s |",
              f"| amplitude ratio magnet / gravity | about 2 | {f['amplitude_ratio_magnetic_to_gravity']:.2f} |",
              f"| wall peak gravity / magnet | not reduced by the magnet | {f['wall_peak_gravity_N']:.2f} N / "
              f"{f['wall_peak_magnetic_N']:.2f} N |",
              f"| pulses at the lower gauge gravity / magnet | no tail with the magnet | {f['pulses_gravity']} / "
              f"{f['pulses_magnetic']} |", "",
              "Dashpot scan on the fitted power law:", "",
              "| dashpot (kg/s) | Table 1 RMS | speed gravity (m/s) | FWHM / base duration (us) | speed magnet (m/s) "
              "| amplitude ratio |",
              "|---|---|---|---|---|---|"]
    for s in f["dashpot_scan"]:
        lines.append(f"| {s['contact_damping_kg_per_s']:g} | {s['table1_rms_relative']:.1%} | "
                     f"{s['gravity_speed_m_per_s']:.0f} | {s['gravity_duration_s'] * 1e6:.0f} / "
                     f"{(s['gravity_base_duration_s'] or math.nan) * 1e6:.0f} | "
                     f"{s['magnetic_speed_m_per_s']:.0f} | {s['amplitude_ratio']:.2f} |")
    st = f["steel"]
    lines += ["", f"Steel-21: E = {st['youngs_modulus_Pa'] / 1e9:.0f} ± {st['youngs_modulus_std_Pa'] / 1e9:.0f} GPa "
              f"(published constants: {st['published_modulus_Pa'] / 1e9:.0f} GPa): {st['gravity_speed_m_per_s']:.0f} "
              f"and {st['magnetic_speed_m_per_s']:.0f} m/s against 580 and 688 m/s."]
    return "\n".join(lines) + "\n"
