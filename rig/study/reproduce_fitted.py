"""`rig reproduce daraio2006 --fitted`: model families fitted to the published experiment.

1. Each family of rig.study.fitted_families (the published Hertz law, the elastic power
   law, dashpots, friction on the holder, elastic-plastic contacts where this version has
   the law) fitted jointly to Table 1's ten points (errors in variables) and Fig. 3's
   observations (rig.fit.joint), and judged by held-out prediction (rig.study.fitted_assess):
   Table 1's linearised leave-one-out, and the magnetic data predicted by the fit to the
   gravity-only data. A family is kept only where it meets every Table 1 and Fig. 3 target
   (rig.study.reproduce_fitted_report.observed_targets); of those, the one that predicts
   held-out data best; none where none meets them (each row's "fails" names what it
   misses and by how much). BIC is reported beside.
   Each family's fit: ``starts`` local fits, after a global search where asked
   (rig.study.fitted_assess.SearchPlan), its evaluations cached in DIR/evaluations/.
2. The kept family's shots at the published 0.89 m/s, with and without the magnet, measured
   as Fig. 3's observations are (rig.fit.observations.kinds), against the published
   experiment: the first shot on a fresh chain ("compared_shot"), and the shots after it on
   the same chain (rig.study.fitted_shots.shot_history); each parameter's window in which
   every target still holds (rig.study.fitted_windows); its parameters in
   DIR/fitted_scene.toml (the ptfe52_gravity scene), written only for a fit that stands for
   the scene (rig.fit.checks.unusable). Table 1's striker velocities with the drops they need.
3. Dissipation: a dashpot scanned on the elastic power law's fitted E and n.
4. Steel-21: its modulus fitted to the two published speeds (580 and 688 m/s at 0.44 m/s).
"""
from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from instruments.files import write_text
from rig.experiment import scene as scene_io
from rig.experiment.shot import Rig
from rig.fit.evaluate import curves
from rig.fit.points import VELOCITY_FACTORS, PointObjective, striker_drops
from rig.fit.report import fitted_scene_text
from rig.study.fitted_assess import SearchPlan, assess, choose
from rig.study.fitted_families import FAMILIES, MAGNETIC_SCENE, SCENE, fig3_observations, table1_points
from rig.study.fitted_shots import fitted_shots, shot_history
from rig.study.fitted_windows import Targets, windows
from rig.study.reproduce_fitted_report import PUBLISHED, markdown, misses, targets

COMPARED = ("the first shot: each figure is of a fresh chain's first shot (chain.previous_shots = 0; the paper "
            "does not say which shot of a campaign a figure is); \"shot_history\" gives the kept set's shots after "
            "it on the same chain, \"settled_fig3_misses\" the Fig. 3 targets the last of them misses")
"""Which shot --fitted compares with the published experiment ("compared_shot")."""
POWER_LAW = "elastic power law"
LEGACY_NAMES = {"power law": POWER_LAW, "power law + dashpot": "dashpot"}
"""Rows of "models" under the names earlier versions gave them (the same rows)."""
"""The family whose fitted E and n the dashpot scan holds ("power_law_shots": its shots)."""
DASHPOTS = (0.0, 0.1, 0.4, 1.6)  # kg/s
FITTED_SCENE = "fitted_scene.toml"
KEPT_KEYS = ("table1_chi2_per_dof", "table1_rms_relative", "table1_max_sigma", "table1_max_relative",
             "table1_unreachable", "table1_points_both_conversions", "parameters",
             "fig3", "gravity_fit_predicts_magnetic_rms_relative", "gravity_only_fit", "ptfe52_gravity_speed_m_per_s",
             "ptfe52_magnetic_speed_m_per_s", "ptfe52_gravity_duration_s", "ptfe52_gravity_base_duration_s",
             "amplitude_ratio_magnetic_to_gravity", "contact_force_ratio_magnetic_to_gravity", "wall_peak_gravity_N",
             "wall_peak_magnetic_N", "pulses_gravity", "pulses_magnetic", "fitted_scene", "windows", "shot_history",
             "settled_fig3_misses")
"""The "fitted" block's keys that describe the kept family (rig reproduce --json).
"amplitude_ratio_magnetic_to_gravity" is, despite its name, the ratio of the leading pulses'
F_d (the largest dynamic CONTACT force at the two gauge beads, the truth analysis), magnet over
gravity; "contact_force_ratio_magnetic_to_gravity" is the same number under a name that says
so. The ratio of the gauge READINGS' peaks that Fig. 3 compares (about 2) is
fig3["gauge_ratio_magnetic_to_gravity"].
"table1_points_both_conversions": Table 1's points against the kept set's F_d both ways, its
contact forces (what the fit compares) and the paper's elastic conversion of its gauge
readings (rig.fit.amplitudes)."""


def reproduce_fitted(out, progress=None, families=FAMILIES, starts: int = 1, generations: int = 0, seed: int = 0,
                     detail=None) -> dict:
    """The model families (default: every one) fitted to Table 1 and Fig. 3, compared and
    judged (module doc); fitted.json, fitted.md and, for the kept family, fitted_scene.toml
    written to ``out``, each family's evaluations cached in out/evaluations/ (the same run
    again replays them). ``starts`` local fits per family, after a global search of
    ``generations`` generations drawn from ``seed`` where > 0 (rig.fit.globalsearch);
    ``progress`` told each step, ``detail`` each fit's and search's lines."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    tell = progress or (lambda *a: None)
    pts, obs = table1_points(), fig3_observations()
    search = SearchPlan(starts, generations, seed, out / "evaluations", detail)
    judged: list = []
    for f in families:
        judged.append(assess(f, pts, obs, tell, judged, search))
    shots = {}
    for a in judged:
        if a.result is not None:
            shots[a.family.name] = fitted_shots(list(a.overrides), a.family.magnetic)
            a.row["fig3"] = shots[a.family.name]["fig3"]
            tell(f"{a.family.name}: shots")
    for a in judged:  # each family's row says what it misses; only one that misses nothing may be kept
        if a.result is not None:
            a.row["fails"] = misses(a.row)
    best = choose([a for a in judged if a.result is not None and not a.row["fails"]])
    power = next((a for a in judged if a.family.name == POWER_LAW), None)
    fitted: dict = {"model": None if best is None else best.family.name,
              "selection": "lowest held-out chi2: Table 1's linearised leave-one-out plus the magnetic data "
                           "predicted by the fit to the gravity-only data, among the converged joint fits that "
                           "meet every Table 1 and Fig. 3 target (a row's \"fails\" names what it misses)",
              "models": {a.family.name: a.row for a in judged}, "power_law_shots": shots.get(POWER_LAW),
              "dashpot_scan": _dashpot_scan(pts, list(power.overrides), tell) if power and power.result else [],
              "published": PUBLISHED}
    fitted["steel"] = _steel(tell, best is not None and "chain.contact_law=thornton" in best.overrides)
    for old, name in LEGACY_NAMES.items():  # the rows' names of earlier versions, kept
        if name in fitted["models"]:
            fitted["models"][old] = fitted["models"][name]
    (out / FITTED_SCENE).unlink(missing_ok=True)
    if best is None:  # every key of the kept model's, none with a value, and why
        fitted.update(dict.fromkeys(KEPT_KEYS))
        fitted["no_fitted_scene"] = ("no family meets every Table 1 and Fig. 3 target with a converged joint fit "
                                     "and both held-out predictions (each family's \"fails\" names what it misses)")
    else:
        fitted.update(_kept(best, shots[best.family.name], out))
        fitted.update(_kept_around(best, pts, obs, tell, detail))
    fitted["compared_shot"] = COMPARED
    v0 = scene_io.load(SCENE).values["striker"]["velocity"]
    fitted["table1_striker_drops"] = striker_drops(SCENE, [], [v0 * f for f in VELOCITY_FACTORS])
    fitted["targets"] = targets(fitted)
    write_text(out / "fitted.json", json.dumps(fitted, indent=1))
    write_text(out / "fitted.md", markdown(fitted))
    return fitted


def _kept_around(best, pts, obs, tell, detail) -> dict:
    """The kept set's one-dimensional windows (rig.study.fitted_windows) and its shots on
    one chain (rig.study.fitted_shots.shot_history), with what the last of them misses."""
    theta = best.result.estimate
    block: dict = {"windows": windows(Targets(best.family, pts, obs, theta), theta, detail)}
    tell(f"{best.family.name}: windows")
    history = shot_history(list(best.overrides), best.family.magnetic)
    block["shot_history"] = history
    block["settled_fig3_misses"] = [m for m in misses({"fig3": history[-1]["fig3"]}) if "Table 1" not in m["target"]]
    tell(f"{best.family.name}: shot history")
    return block


def _kept(best, shots: dict, out: Path) -> dict:
    """The kept family's figures, ``shots`` (fitted_shots) and fitted scene (written where
    its fit is usable)."""
    row, r = best.row, best.result
    g, m = shots[SCENE], shots[MAGNETIC_SCENE]
    block = {k: row[k] for k in ("table1_chi2_per_dof", "table1_rms_relative", "table1_max_sigma",
                                 "table1_unreachable", "table1_points_both_conversions")}
    block.update({
        "table1_max_relative": row["max_relative"], "parameters": row["parameters"], "fig3": shots["fig3"],
        "gravity_fit_predicts_magnetic_rms_relative": row["magnetic_from_gravity"]["rms_relative"],
        "gravity_only_fit": row["magnetic_from_gravity"]["parameters"],
        "ptfe52_gravity_speed_m_per_s": g["speed_m_per_s"], "ptfe52_magnetic_speed_m_per_s": m["speed_m_per_s"],
        "ptfe52_gravity_duration_s": g["duration_s"], "ptfe52_gravity_base_duration_s": g["base_duration_s"],
        "amplitude_ratio_magnetic_to_gravity": _ratio(shots),
        "contact_force_ratio_magnetic_to_gravity": _ratio(shots),
        "wall_peak_gravity_N": g["wall_peak_N"], "wall_peak_magnetic_N": m["wall_peak_N"],
        "pulses_gravity": g["pulses"], "pulses_magnetic": m["pulses"]})
    if row["unusable"]:
        block.update({"fitted_scene": None, "no_fitted_scene": row["unusable"]})
    else:
        path = out / FITTED_SCENE
        fixed = [o for o in best.overrides if o.split("=", 1)[0] not in r.keys]
        write_text(path, fitted_scene_text(SCENE, fixed, r))
        block["fitted_scene"] = str(path)
    return block


def _dashpot_scan(pts, law: list, tell) -> list:
    """A linear dashpot added to the elastic power law's fitted E and n (held): Table 1's
    relative RMS and the gravity and magnetic shots at each damping."""
    scan = []
    for mu in DASHPOTS:
        extra = [] if mu == 0 else ["chain.contact_law=dashpot", f"chain.contact_damping={mu!r}"]
        s = fitted_shots(law + extra)
        obj = PointObjective(SCENE, (), pts, law + extra)
        (model,) = obj.evaluate([np.zeros(0)])
        rel = obj.relative_residuals(model)
        scan.append({"contact_damping_kg_per_s": mu, "table1_rms_relative": float(np.sqrt(np.nanmean(rel ** 2))),
                     "gravity_speed_m_per_s": s[SCENE]["speed_m_per_s"],
                     "gravity_duration_s": s[SCENE]["duration_s"],
                     "gravity_base_duration_s": s[SCENE]["base_duration_s"],
                     "magnetic_speed_m_per_s": s[MAGNETIC_SCENE]["speed_m_per_s"],
                     "amplitude_ratio": _ratio(s), "fig3": s["fig3"]})
        tell(f"dashpot {mu:g} kg/s")
    return scan


def _ratio(shots: dict) -> float:
    """The ratio of the leading pulses' F_d (the truth analysis), magnet over gravity."""
    a, b = shots[MAGNETIC_SCENE]["amplitude_N"], shots[SCENE]["amplitude_N"]
    return float(a / b) if a and b else math.nan


def _steel(tell, plastic: bool) -> dict:
    """Steel-21 fitted to its two published speeds at 0.44 m/s (10% each), with the kept
    family's contact law and steel's own parameters: for an elastic family its modulus, for
    an elastic-plastic one its yield force at the published modulus (steel's contacts, not
    PTFE's, so none of PTFE's values; no rate law, hold or dashpot). A 1-D weighted least
    squares over a grid (log-spaced for the yield force), refined by parabola."""
    scenes = ("steel21_gravity", "steel21_magnetic")
    target = np.array([PUBLISHED["steel_gravity_speed"], PUBLISHED["steel_magnetic_speed"]])
    if plastic:
        key, grid, law = "chain.yield_force", np.geomspace(0.5, 200.0, 15), ["chain.contact_law=thornton"]
    else:
        key, grid, law = "chain.youngs_modulus", np.linspace(120e9, 260e9, 15), []
    sets = [law + [f"{key}={float(x)!r}"] for x in grid]
    speeds = np.array([[c.speed[0] for c in curves(s, sets, [0.44])] for s in scenes]).T
    chi2 = np.sum(((speeds - target) / (0.1 * target)) ** 2, axis=1)
    k = int(np.clip(np.nanargmin(chi2), 1, grid.size - 2))
    x = np.log(grid) if plastic else grid
    a, b, _ = np.polyfit(x[k - 1:k + 2], chi2[k - 1:k + 2], 2)
    best = float(-b / (2 * a)) if a > 0 else float(x[k])
    value = float(np.exp(best)) if plastic else best
    std = float(math.sqrt(2 / a)) * (value if plastic else 1.0) if a > 0 else math.nan
    fitted = [c.speed[0] for s in scenes for c in curves(s, [law + [f"{key}={value!r}"]], [0.44])]
    tell("steel")
    published = Rig.from_scene("steel21_gravity").chain.beads[-1].material.E
    out = {"law": "thornton" if plastic else "hertz", "fitted_key": key,
           "youngs_modulus_Pa": published if plastic else value,
           "youngs_modulus_std_Pa": math.nan if plastic else std,
           "gravity_speed_m_per_s": fitted[0], "magnetic_speed_m_per_s": fitted[1], "published_modulus_Pa": published}
    if plastic:
        out.update({"yield_force_N": value, "yield_force_std_N": std})
    return out
