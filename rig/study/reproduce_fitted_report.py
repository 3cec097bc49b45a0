"""What `rig reproduce daraio2006 --fitted` states: the published numbers, the targets a
fitted model is held to (each met or not, never tuned to), and fitted.md.

The targets: Table 1 fitted to a relative RMS of at most 7%, chi2/dof at most 1, no point
beyond 2 sd and every point reachable (a striker velocity of the model's curve gives its
amplitude); Fig. 3's figures in the windows of the project's issue on it: gravity speed
116-142 m/s (129 +- 10%), the leading pulse's full duration at the upper gauge 120-204 us, a
train (at least 2 pulses above 10% of the leading one at the lower gauge), magnetic speed
200-244 m/s, gauge-reading ratio magnet / gravity 1.5-2.5, the wall's peak not reduced by the
magnet, the magnetic tail at the lower gauge at most 10% of the leading pulse; steel's two
speeds within the paper's 10%.
"""
from __future__ import annotations

import math

PUBLISHED = {"gravity_speed": 129.0, "gravity_duration_s": 170e-6, "magnetic_speed": 222.0, "amplitude_ratio": 2.0,
             "steel_gravity_speed": 580.0, "steel_magnetic_speed": 688.0}

FIG3 = (  # key, what, published, window (lo, hi)
    ("gravity_speed_m_per_s", "speed, gravity only (m/s)", "129", (116.0, 142.0)),
    ("gravity_duration_us", "full duration, gravity only, upper gauge (us)", "170", (120.0, 204.0)),
    ("gravity_pulses_lower_gauge", "pulses at the lower gauge, gravity only", "a train", (2.0, math.inf)),
    ("magnetic_speed_m_per_s", "speed with 2.38 N (m/s)", "222", (200.0, 244.0)),
    ("gauge_ratio_magnetic_to_gravity", "gauge readings' peak ratio magnet / gravity", "about 2", (1.5, 2.5)),
    ("wall_peak_gravity_N", "wall peak, gravity only (N)", "-", None),
    ("wall_peak_magnetic_N", "wall peak with the magnet (N)", "not reduced", None),
    ("magnetic_tail_relative", "tail with the magnet, lower gauge (of the leading pulse)", "not seen", (0.0, 0.10)),
    ("magnetic_tail_shoulder_relative", "the tail's slow shoulder with the magnet, lower gauge (of the leading pulse)",
     "-", None),
)
TABLE1 = (("table1_rms_relative", "Table 1 relative RMS <= 7%", 0.07),
          ("table1_chi2_per_dof", "Table 1 chi2/dof <= 1", 1.0),
          ("table1_max_sigma", "no Table 1 point beyond 2 sd", 2.0),
          ("table1_unreachable", "every Table 1 point reachable (points no striker velocity reaches)", 0))
STEEL = (("gravity_speed_m_per_s", "steel speed, gravity only (m/s)", 580.0),
         ("magnetic_speed_m_per_s", "steel speed with 2.38 N (m/s)", 688.0))


INTRO = ("Each family fitted jointly to Table 1 (10 points, errors in both coordinates) and Fig. 3's observations "
         "(speeds, duration, gauge ratio, tail). Held-out prediction: Table 1's leave-one-out is LINEARISED (PRESS, "
         "r_i / (1 - h_ii) at the joint optimum, exact for a linear model; no refits), and the magnetic data (points "
         "and observations) are predicted by the family fitted to the gravity-only data.")
FAMILY_HEADER = ("| family | parameters (SI) | joint chi2 / dof | BIC | Table 1 chi2/dof | Table 1 RMS | worst (sd) "
                 "| leave-one-out chi2, RMS | magnetic from gravity chi2 / n, RMS |")
RATIOS = ("The gauge ratio compares the gauges' READINGS (the peaks of the upper gauge's trace, as Fig. 3 does); "
          "the JSON's amplitude_ratio_magnetic_to_gravity (also contact_force_ratio_magnetic_to_gravity) is NOT a "
          "reading ratio: it is the ratio of the leading pulses' F_d, the largest dynamic contact force at the two "
          "gauge beads (the truth analysis):")
SCAN_HEADER = ("| dashpot (kg/s) | Table 1 RMS | speed gravity (m/s) | FWHM / base duration (us) | speed magnet (m/s) "
               "| F_d ratio |")


def _inside(value, window) -> bool | None:
    if value is None or not math.isfinite(value):
        return None
    return bool(window[0] <= value <= window[1])


def observed_targets(row: dict) -> list:
    """[{"target", "value", "met", "by"}] of Table 1 and Fig. 3 for a family's row (its
    table1_* keys and its "fig3" figures): met None where it has no value, ``by`` how far
    outside the window the value lies (in the target's unit; 0 where met, None without one)."""
    out = []
    for key, what, limit in TABLE1:
        v = row.get(key)
        out.append({"target": what, "value": v, "met": _inside(v, (-math.inf, limit)), "by": _beyond(v, (-math.inf,
                                                                                                       limit))})
    fig3 = row.get("fig3") or {}
    for key, what, published, window in FIG3:
        if window is not None:
            v = fig3.get(key)
            out.append({"target": f"{what}: {published}, window {window[0]:g} to {window[1]:g}",
                        "value": v, "met": _inside(v, window), "by": _beyond(v, window)})
    g, m = fig3.get("wall_peak_gravity_N"), fig3.get("wall_peak_magnetic_N")
    out.append({"target": "the magnet does not reduce the wall's peak", "value": [g, m],
                "met": None if g is None or m is None else bool(m >= g),
                "by": None if g is None or m is None else max(g - m, 0.0)})
    return out


def misses(row: dict) -> list:
    """The targets a family's row does not meet: [{"target", "value", "by"}]."""
    return [{k: t[k] for k in ("target", "value", "by")} for t in observed_targets(row) if t["met"] is not True]


def _beyond(value, window):
    if value is None or not math.isfinite(value):
        return None
    return float(max(window[0] - value, value - window[1], 0.0))


def targets(fitted: dict) -> list:
    """[{"target", "value", "met"}] of the kept model (met None where it has no value)."""
    out = [{k: t[k] for k in ("target", "value", "met")} for t in observed_targets(fitted)]
    for key, what, speed in STEEL:
        v = fitted["steel"].get(key)
        out.append({"target": f"{what}: {speed:g} +- 10%", "value": v,
                    "met": _inside(v, (0.9 * speed, 1.1 * speed))})
    return out


def _f(x, fmt: str) -> str:
    return "-" if x is None or (isinstance(x, float) and not math.isfinite(x)) else format(x, fmt)


def _family_line(name: str, b: dict) -> str:
    if b.get("skipped") or b.get("failed"):
        return f"| {name} | {'skipped' if b.get('skipped') else 'failed'}: {b.get('skipped') or b.get('failed')} " \
               "| | | | | | | |"
    pars = ", ".join(f"{k.split('.')[-1]} {v['estimate']:.4g} ± {v['std']:.2g}" for k, v in b["parameters"].items())
    mg = b.get("magnetic_from_gravity", {})
    held = (f"{mg['chi2']:.1f} / {mg['n']}, {mg['rms_relative']:.1%}" if "chi2" in mg
            else f"failed: {mg.get('failed', '-')}")
    return (f"| {name} | {pars} | {b['chi2']:.2f} / {b['dof']} | {b['bic']:.2f} | "
            f"{_f(b['table1_chi2_per_dof'], '.2f')} | {b['table1_rms_relative']:.1%} | {b['table1_max_sigma']:.2f} | "
            f"{b['loo_chi2']:.2f}, {b['loo_rms_relative']:.1%} | {held} |")


LEGACY = ("power law", "power law + dashpot")
"""Rows that repeat a family's under an earlier version's name (not shown twice)."""


def markdown(f: dict) -> str:
    """fitted.md: the families, their Fig. 3 figures against the published ones, the
    targets, the dashpot scan and steel."""
    models = {n: b for n, b in f["models"].items() if n not in LEGACY}
    fitted = {n: b for n, b in models.items() if "fig3" in b}
    lines = ["# Daraio 2006, model families fitted to the experiment", "",
             INTRO, "", FAMILY_HEADER,
             "|---|---|---|---|---|---|---|---|---|"]
    lines += [_family_line(n, b) for n, b in models.items()]
    lines += ["", f"Kept ({f['selection']}): **{f['model'] or 'none'}**."]
    for n, b in models.items():
        if b.get("fails"):
            lines.append(f"- {n} fails: " + "; ".join(f"{m['target']} ({_shown(m['value'])}, by {_shown(m['by'])})"
                                                    for m in b["fails"]))
    lines += ["", "| Fig. 3 figure | published | " + " | ".join(fitted) + " |",
              "|---|---|" + "---|" * len(fitted)]
    for key, what, published, _ in FIG3:
        lines.append(f"| {what} | {published} | "
                     + " | ".join(_f(b["fig3"].get(key), ".3g") for b in fitted.values()) + " |")
    ratio = _f(f.get("amplitude_ratio_magnetic_to_gravity"), ".2f")
    lines += ["", f"{RATIOS} {ratio} for the kept model.",
              "", "Targets (the kept model; not tuned to):", ""]
    lines += [f"- {t['target']}: {_shown(t['value'])}: "
              f"{'met' if t['met'] else 'NOT met' if t['met'] is False else 'no value'}" for t in f["targets"]]
    scene = f.get("fitted_scene")
    lines += ["", f"Fitted scene: {scene} (`rig shot` fires it)." if scene
              else f"No fitted scene written: {f.get('no_fitted_scene')}."]
    lines += _conversions(f.get("table1_points_both_conversions"))
    lines += _windows(f.get("windows")) + _history(f) + _drops(f.get("table1_striker_drops")) + _sources(models)
    lines += ["", "Dashpot scan on the elastic power law's fitted E and n:", "",
              SCAN_HEADER, "|---|---|---|---|---|---|"]
    for s in f["dashpot_scan"]:
        lines.append(f"| {s['contact_damping_kg_per_s']:g} | {s['table1_rms_relative']:.1%} | "
                     f"{_f(s['gravity_speed_m_per_s'], '.0f')} | {_us(s['gravity_duration_s'])} / "
                     f"{_us(s['gravity_base_duration_s'])} | "
                     f"{_f(s['magnetic_speed_m_per_s'], '.0f')} | {_f(s['amplitude_ratio'], '.2f')} |")
    st = f["steel"]
    if st.get("law") == "thornton":
        steel = (f"Steel-21 (the kept family's elastic-plastic law with steel's own parameters: the published "
                 f"E = {st['published_modulus_Pa'] / 1e9:.0f} GPa, its yield force fitted to its two speeds): "
                 f"F_y = {st['yield_force_N']:.3g} ± {st['yield_force_std_N']:.2g} N: "
                 f"{st['gravity_speed_m_per_s']:.0f} and {st['magnetic_speed_m_per_s']:.0f} m/s against 580 and "
                 "688 m/s.")
    else:
        steel = (f"Steel-21 (its own Hertz law, its modulus fitted to its two speeds): E = "
                 f"{st['youngs_modulus_Pa'] / 1e9:.0f} ± {st['youngs_modulus_std_Pa'] / 1e9:.0f} GPa (published "
                 f"constants: {st['published_modulus_Pa'] / 1e9:.0f} GPa): {st['gravity_speed_m_per_s']:.0f} and "
                 f"{st['magnetic_speed_m_per_s']:.0f} m/s against 580 and 688 m/s.")
    lines += ["", steel]
    return "\n".join(lines) + "\n"


CONVERSIONS = ("Table 1's points against the kept set's F_d two ways: (1) its largest dynamic contact force at the "
               "gauge beads (the truth analysis; what the fit compares), (2) its gauge readings F_m,e converted as the "
               "paper converted the experiment's, F_d = beta(F_m/F_0) F_m,e of the elastic (Hertz) chain, from the "
               "same shots. Model V_s at each point's F_d, residual in sd (effective variance):")


def _conversions(both) -> list:
    """Table 1's points against the kept set's F_d both ways (rig.fit.amplitudes)."""
    if not both:
        return []
    out = ["", CONVERSIONS, "", "| magnet.force | F_d (N) | V_s (m/s) | model V_s, (1) contact force (m/s) "
                                "| (1) residual (sd) | model V_s, (2) elastic conversion (m/s) | (2) residual (sd) |",
           "|---|---|---|---|---|---|---|"]
    for p in both["points"]:
        magnet = next((o.split("=", 1)[1] for o in p["configuration"] if o.startswith("magnet.force=")), "-")
        cells = (_f(p["model_V_s_contact_force_m_per_s"], ".1f"), _f(p["residual_contact_force_sd"], "+.2f"),
                 _f(p["model_V_s_elastic_conversion_m_per_s"], ".1f"), _f(p["residual_elastic_conversion_sd"], "+.2f"))
        out.append(f"| {magnet} | {p['F_d_N']:.3g} | {p['V_s_m_per_s']:.0f} | " + " | ".join(cells) + " |")
    ratios = [e / c for cv in both["curves"] for c, e in zip(cv["contact_force_N"], cv["elastic_conversion_N"])
              if c and e]
    spread = f"; (2)'s F_d over (1)'s on the curves' shots: {min(ratios):.3f} to {max(ratios):.3f}" if ratios else ""
    rms = (_f(both["rms_relative_contact_force"], ".1%"), _f(both["rms_relative_elastic_conversion"], ".1%"))
    out += ["", f"chi2/dof ({both['dof']} dof): (1) {_f(both['chi2_per_dof_contact_force'], '.3f')}, "
                f"(2) {_f(both['chi2_per_dof_elastic_conversion'], '.3f')}; relative RMS: (1) {rms[0]}, (2) {rms[1]}"
                f"{spread}. The fit uses (1)."]
    return out


def _windows(windows) -> list:
    """The kept set's windows (rig.study.fitted_windows), one row a parameter."""
    if not windows:
        return []
    out = ["", "Each parameter's window in which the kept set still meets every target (the others held; a scan "
               "over its bounds, edges bisected to 0.2%):", "",
           "| parameter | value | window | relative | fails below | fails above |", "|---|---|---|---|---|---|"]
    for key, w in windows.items():
        if w["window"] is None:
            out.append(f"| {key} | {w['value']:.6g} | none: the set misses a target here | | | |")
            continue
        lo, hi = (("<= " if w["open"][0] else "") + f"{w['window'][0]:.6g}",
                  (">= " if w["open"][1] else "") + f"{w['window'][1]:.6g}")
        unit = "" if w["unit"] == "1" else " " + w["unit"]
        out.append(f"| {key} | {w['value']:.6g}{unit} | {lo} .. {hi} | {w['relative'][0]:+.2%} .. "
                   f"{w['relative'][1]:+.2%} | {'; '.join(w['failing_below']) or '-'} | "
                   f"{'; '.join(w['failing_above']) or '-'} |")
    return out


def _history(f: dict) -> list:
    """Which shot is compared, and the kept set's shots on one chain."""
    out = ["", f"Compared: {f.get('compared_shot')}."]
    history = f.get("shot_history")
    if not history:
        return out
    out += ["", "| shot on one chain | " + " | ".join(what for _, what, _, _ in FIG3) + " |",
            "|---|" + "---|" * len(FIG3)]
    for h in history:
        out.append(f"| {h['shot']} | " + " | ".join(_f(h["fig3"].get(key), ".4g") for key, _, _, _ in FIG3) + " |")
    missed = f.get("settled_fig3_misses") or []
    out += ["", "The last of them misses: " + ("; ".join(f"{m['target']} ({_shown(m['value'])})" for m in missed)
                                            if missed else "nothing") + "."]
    return out


def _drops(drops) -> list:
    """The Table 1 curves' striker velocities, each with its drop and where it is released."""
    if not drops or not drops["drops"]:
        return []
    speeds = ", ".join(f"{d['velocity_m_per_s']:.3g}" for d in drops["drops"])
    heights = ", ".join(f"{100 * d['drop_height_m']:.3g}" for d in drops["drops"])
    return ["", f"Table 1's curves strike at {speeds} m/s: drops of {heights} cm (h = v^2 / 2g, no loss on the "
                f"way); the {1000 * drops['holder_length_m']:.0f} mm tube leaves {100 * drops['free_length_m']:.3g} "
                "cm above the chain, so the higher drops release the striker above its open top."]


def _sources(models: dict) -> list:
    """Where each fitted key's bounds come from (once a key)."""
    sources: dict = {}
    for b in models.values():
        sources.update({k: v for k, v in (b.get("bounds_sources") or {}).items() if v})
    return ["", "Bounds and their sources:", ""] + [f"- {k}: {v}" for k, v in sources.items()] if sources else []


def _us(seconds) -> str:
    return "-" if seconds is None else _f(seconds * 1e6, ".0f")


def _shown(v) -> str:
    if isinstance(v, list):
        return " / ".join(_f(x, ".3g") for x in v)
    return _f(v, ".3g")
