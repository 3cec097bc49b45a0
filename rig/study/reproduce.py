"""`rig reproduce daraio2006`: the published study, re-run on the virtual rig.

Runs the published scenes (20 seeds each for the virtual experiment's spread), striker
velocity sweeps of the four configurations of Table 1, and a striker mass sweep, then
writes Table 1 (virtual experiment, numerics, long-wave theory) as Markdown and CSV, a
summary, results.json and the figures, in that order. Each sweep point's V/div is chosen from the
noise-free truth (1-2-5 steps, pulses near 5 divisions) as a physicist would set the scope.
Fixed seeds: re-running gives identical numbers.
"""
from __future__ import annotations

import csv
import json
import math
from pathlib import Path

import numpy as np

from instruments.analysis import PeakRules, find_pulses, leading, reflection_time, solitary_train
from instruments.files import atomic_write, write_text
from rig.errors import invalid
from rig.experiment.measure import midway_static_force, setup_for, shot_blocks
from rig.experiment.shot import Rig
from rig.study.reproduce_figures import figure_specs
from rig.study.sweep import seeds_for
from rig.theory.longwave import solitary_wave_speed, sonic_vacuum_speed, sound_speed
from rig.viz import figures

CONFIGS = [  # (material, precompression label, scene)
    ("PTFE", "gravity", "ptfe52_gravity"), ("PTFE", "2.38 N", "ptfe52_magnetic"),
    ("steel", "gravity", "steel21_gravity"), ("steel", "2.38 N", "steel21_magnetic")]
OTHER_SCENES = ["ptfe52_magnetic_4p25", "ptfe20_gravity"]
PUBLISHED_C0 = {"ptfe52_gravity": 92.6, "ptfe52_magnetic": 211.2,
                "steel21_gravity": 292.6, "steel21_magnetic": 539.6}
VELOCITY_FACTORS = (0.25, 0.5, 1.0, 1.5, 2.0, 3.0)
MASS_RATIOS = (1, 2, 3, 4, 6, 8)
SEEDS = 20
STUDIES = ("daraio2006",)


def autoscaled(scene: str, overrides=()) -> Rig:
    """The scene with each gauge and wall channel's V/div set so the pulse spans ~5 div."""
    rig = Rig.from_scene(scene, overrides)
    truth = rig.truth()
    extra = []
    peaks = {}  # expected peak volts per channel
    for gauge in rig.gauges:
        g = truth.gauges[gauge.name]
        peaks[gauge.channel] = gauge.settings.sensitivity * float(np.max(g.average_force - g.average_force[0]))
    if rig.wall_sensor is not None:
        ws = rig.wall_sensor
        peaks[ws.channel] = ws.settings.sensitivity * float(np.max(truth.wall() - truth.wall()[0]))
    for ch, v in peaks.items():
        extra.append(f"scope.channels.{ch}.volts_per_div={_step_125(v / 5.0)!r}")
    extra.append(f"scope.trigger.level={0.15 * peaks[rig.scope.trigger.source]!r}")
    scaled = Rig.from_scene(scene, list(overrides) + extra)
    scaled.use_solution(rig.solution())  # the scope's settings alone differ: the same chain, the same solve
    return scaled


def _step_125(x: float) -> float:
    """The smallest 1-2-5 step >= x (V/div)."""
    decade = 10 ** math.floor(math.log10(x))
    return next(m * decade for m in (1, 2, 5, 10) if m * decade >= x * (1 - 1e-12))


def _experiment(rig: Rig, seeds) -> dict:
    v, a = [], []
    for s in seeds:
        m = shot_blocks(rig, rig.fire(seed=s))["measured"]
        if m["speed_m_per_s"] is not None:
            v.append(m["speed_m_per_s"])
            a.append(m["amplitude_N"])
    return {"speed_mean": float(np.mean(v)), "speed_sd": float(np.std(v)),
            "amplitude_mean": float(np.mean(a)), "amplitude_sd": float(np.std(a)), "shots": len(v)}


def _theory(rig: Rig, F0: float, Fm: float) -> dict:
    bead = rig.chain.beads[-1]
    m = bead.material
    return {"c0": float(sound_speed(m.E, m.nu, m.rho, bead.diameter, F0)),
            "eq1": float(solitary_wave_speed(m.E, m.nu, m.rho, bead.diameter, F0, Fm)),
            "eq4": float(sonic_vacuum_speed(m.E, m.nu, m.rho, bead.diameter, Fm))}


def reproduce(study: str, out, progress=None) -> dict:
    if study not in STUDIES:
        raise invalid("study", study, f"known: {', '.join(STUDIES)}")
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    tick = progress or (lambda *a: None)
    results: dict = {"table1": [], "scenes": {}, "sweeps": {}, "mass_ratio": []}  # JSON-ready
    rigs = {}
    for scene in [c[2] for c in CONFIGS] + OTHER_SCENES:
        rig = rigs[scene] = Rig.from_scene(scene)
        t = rig.truth_analysis()
        F0 = midway_static_force(rig)
        results["scenes"][scene] = {"truth": t.as_dict(), "F0": F0,
                                    "experiment": _experiment(rig, seeds_for(1, SEEDS)),
                                    "theory": _theory(rig, F0, F0 + t.amplitude_N)}
        tick(f"scene {scene}")
    for _material, _pre, scene in CONFIGS:
        base_v = rigs[scene].striker.velocity
        pts = []
        for k, f in enumerate(VELOCITY_FACTORS):
            rig = autoscaled(scene, [f"striker.velocity={base_v * f!r}"])
            t = rig.truth_analysis()
            shot = rig.fire(seed=seeds_for(2, len(VELOCITY_FACTORS))[k])
            m = shot_blocks(rig, shot)["measured"]
            F0 = midway_static_force(rig)
            pts.append({"velocity": base_v * f, "F0": F0, "truth_speed": t.speed_m_per_s,
                        "truth_Fm": t.amplitude_N + F0, "truth_beta": t.beta,
                        "measured_speed": m["speed_m_per_s"],
                        "measured_Fm": None if m["amplitude_N"] is None else m["amplitude_N"] + F0})
            tick(f"sweep {scene} v = {base_v * f:.3g} m/s")
        results["sweeps"][scene] = pts
    bead_mass = rigs["ptfe52_gravity"].chain.beads[1].mass
    for ratio in MASS_RATIOS:  # without the 0.5 g magnetic bead, itself a heavy impactor on PTFE
        rig = Rig.from_scene("ptfe52_gravity", ["chain.magnetic_bead=false", f"striker.mass={ratio * bead_mass!r}",
                                                "solver.duration=6e-3"])
        t = rig.truth_analysis()
        results["mass_ratio"].append({"ratio": ratio, "pulses_lower_gauge": t.pulses})
        tick(f"striker mass ratio {ratio}")
    results["table1"] = _table1(results, rigs)
    results["summary"] = _summary(results, rigs)
    _write_tables(out, results)
    # the numbers before the figures drawn from them: a disk that fills in the figures leaves them whole
    write_text(out / "results.json", json.dumps(results, indent=1, sort_keys=True))
    for spec in figure_specs(results, rigs):
        figures.draw(out, spec)
    tick("figures")
    return results


def _table1(results, rigs) -> list:
    rows = []
    for material, pre, scene in CONFIGS:
        r = results["scenes"][scene]
        e, t, th = r["experiment"], r["truth"], r["theory"]
        rows.append({"chain": material, "precompression": pre, "F0_N": r["F0"],
                     "Fm_numerics_N": t["amplitude_N"] + r["F0"],
                     "Fm_experiment_N": e["amplitude_mean"] + r["F0"], "Fm_experiment_sd_N": e["amplitude_sd"],
                     "Vs_experiment_m_per_s": e["speed_mean"], "Vs_experiment_sd_m_per_s": e["speed_sd"],
                     "Vs_numerics_m_per_s": t["speed_m_per_s"], "Vs_eq1_m_per_s": th["eq1"],
                     "c0_eq2_m_per_s": th["c0"], "c0_published_m_per_s": PUBLISHED_C0[scene]})
    return rows


def _counts(rig: Rig, role: str) -> tuple:
    """Solitary waves (above 5% of the leading one) at a gauge before the reflection, and
    the time between the first two (s; nan if only one)."""
    truth = rig.truth()
    setup = setup_for(rig)
    ch = getattr(setup, role).channel
    g = next(v for v in truth.gauges.values() if v.channel == ch)
    f = g.average_force - g.average_force[0]
    t = np.arange(f.size) * truth.sample_interval
    lead = leading(find_pulses(t, f, PeakRules()))
    cut = reflection_time(t, {"wall": truth.wall() - truth.wall()[0]}, setup, lead, math.nan)
    train = solitary_train(t, f, lead, cut, PeakRules(), refine=True)
    gap = train[1].time - train[0].time if len(train) > 1 else math.nan
    return len(train), gap


def _summary(results, rigs) -> dict:
    s, sc = {}, results["scenes"]
    for mat, grav, mag in (("PTFE", "ptfe52_gravity", "ptfe52_magnetic"),
                           ("steel", "steel21_gravity", "steel21_magnetic")):
        s[f"{mat}_sound_speed_ratio_magnet_over_gravity"] = sc[mag]["theory"]["c0"] / sc[grav]["theory"]["c0"]
        s[f"{mat}_wall_peak_gravity_N"] = _wall_peak(rigs[grav])
        s[f"{mat}_wall_peak_2p38N_N"] = _wall_peak(rigs[mag])
    for scene in ("ptfe52_gravity", "ptfe52_magnetic", "steel21_gravity", "steel21_magnetic"):
        t = sc[scene]["truth"]
        s[f"{scene}_leading_fwhm_diameters"] = t["width_diameters"]
        d = rigs[scene].chain.beads[-1].diameter
        s[f"{scene}_leading_width_1pct_diameters"] = 2 * t["leading"]["upper"]["rise"] * t["speed_m_per_s"] / d
        for role in ("upper", "lower"):
            n, gap = _counts(rigs[scene], role)
            s[f"{scene}_pulses_at_{role}_gauge"] = n
            s[f"{scene}_first_two_pulses_apart_at_{role}_gauge_diameters"] = gap * t["speed_m_per_s"] / d
    bead = rigs["ptfe52_gravity"].chain.beads[1]
    s["striker_to_bead_mass_ratio_published"] = rigs["ptfe52_gravity"].striker.mass / bead.mass
    return s


def _wall_peak(rig: Rig) -> float:
    w = rig.truth().wall()
    return float(np.max(w) - w[0])


def _write_tables(out: Path, results):
    rows = results["table1"]

    def table_csv(tmp):
        with open(tmp, "w", newline="") as fh:
            wr = csv.DictWriter(fh, fieldnames=list(rows[0]))
            wr.writeheader()
            wr.writerows(rows)

    atomic_write(out / "table1.csv", table_csv)
    lines = ["| chain | precompression | F_0 (N) | F_m numerics (N) | F_m virtual exp. (N) | "
             "V_s virtual exp. (m/s) | V_s numerics (m/s) | V_s Eq (1) (m/s) | c0 Eq (2) (m/s) | c0 published (m/s) |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['chain']} | {r['precompression']} | {r['F0_N']:.3f} | {r['Fm_numerics_N']:.2f} | "
                     f"{r['Fm_experiment_N']:.2f} ± {r['Fm_experiment_sd_N']:.2f} | "
                     f"{r['Vs_experiment_m_per_s']:.1f} ± {r['Vs_experiment_sd_m_per_s']:.1f} | "
                     f"{r['Vs_numerics_m_per_s']:.1f} | {r['Vs_eq1_m_per_s']:.1f} | {r['c0_eq2_m_per_s']:.1f} | "
                     f"{r['c0_published_m_per_s']:.1f} |")
    write_text(
        out / "table1.md",
        f"Table 1, reproduced: virtual experiment (mean ± sd over {SEEDS} shots), numerics (noise-free truth), "
        "long-wave theory at the numerics' F_m.\n\n" + "\n".join(lines) + "\n")
    s = results["summary"]
    body = ["# Summary", ""]
    body += [f"- {k}: {v:.4g}" if isinstance(v, float) else f"- {k}: {v}" for k, v in sorted(s.items())]
    body += ["", "Striker mass sweep on the 52-bead PTFE chain without its magnetic bead (gravity only):", "",
             "| striker / bead mass | solitary waves at the lower gauge |", "|---|---|"]
    body += [f"| {m['ratio']} | {m['pulses_lower_gauge']} |" for m in results["mass_ratio"]]
    write_text(out / "summary.md", "\n".join(body) + "\n")
