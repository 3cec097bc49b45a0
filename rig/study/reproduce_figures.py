"""The figures of the published study, computed as data (theory curves, traces, beta, the
leading pulse against the exact solitary wave); rig.viz.figures only draws them."""
from __future__ import annotations

import math
from collections.abc import Iterator

import numpy as np

from instruments.analysis import record_forces
from rig.experiment.measure import setup_for
from rig.study.sweep import seeds_for
from rig.theory.longwave import solitary_wave_speed, sonic_vacuum_speed, sound_speed
from rig.theory.solitary import beta as beta_of
from rig.theory.solitary import solitary_wave
from rig.viz.figures import FigureSpec


def figure_specs(results, rigs) -> Iterator[FigureSpec]:
    """The published study's figures as data: theory curves, virtual and numerical traces,
    beta against F_m/F_0 and the leading pulse against the exact solitary wave, each
    computed when it is asked for (a figure that cannot be drawn, on a full disk, leaves the
    later ones uncomputed)."""
    for mat, scenes in (("PTFE", ("ptfe52_gravity", "ptfe52_magnetic")),
                        ("steel", ("steel21_gravity", "steel21_magnetic"))):
        rig = rigs[scenes[0]]
        bead = rig.chain.beads[-1]
        m = bead.material
        F = np.logspace(-1.5, 2.2, 200) if mat == "PTFE" else np.logspace(-1, 2.7, 200)
        curves, sound, series = [], [], []
        for scene, style in zip(scenes, ("C0", "C3")):
            F0 = results["scenes"][scene]["F0"]
            ok = F > F0 * 1.001
            curve = np.full_like(F, np.nan)
            curve[ok] = solitary_wave_speed(m.E, m.nu, m.rho, bead.diameter, F0, F[ok])
            curves.append((f"Eq (1), F_0 = {F0:.3g} N", curve, style + "-"))
            sound.append((f"c0 Eq (2), F_0 = {F0:.3g} N",
                          float(sound_speed(m.E, m.nu, m.rho, bead.diameter, F0)), style))
            pts = results["sweeps"][scene]
            pre = "gravity" if "gravity" in scene else "2.38 N"
            series.append((f"numerics, {pre}", [p["truth_Fm"] for p in pts], [p["truth_speed"] for p in pts],
                           style + "o"))
            meas = [(p["measured_Fm"], p["measured_speed"]) for p in pts if p["measured_speed"] is not None]
            series.append((f"virtual experiment, {pre}", [x for x, _ in meas], [y for _, y in meas], style + "x"))
        curves.append(("Eq (4), sonic vacuum", sonic_vacuum_speed(m.E, m.nu, m.rho, bead.diameter, F), "k--"))
        yield FigureSpec("speed_vs_force", f"speed_vs_force_{mat.lower()}.png",
                         (f"{mat}: solitary wave speed against force", series,
                          {"F_m": F, "curves": curves, "sound": sound}))
        panels = {}
        for scene in scenes:
            r = rigs[scene]
            shot = r.fire(seed=seeds_for(1, 1)[0])
            pre = "gravity only" if "gravity" in scene else "2.38 N magnet"
            setup = setup_for(r, 1.0, 0.0)
            t, f = record_forces(shot.scope, setup)
            panels[(pre, "virtual scope (time from trigger)")] = [
                (f"gauge {g}", t, f[g]) for g in ("upper", "lower")] + [("wall", t, f["wall"])]
            tr = r.truth()
            tt = np.arange(tr.wall_force.size) * tr.sample_interval
            gs = sorted(tr.gauges.values(), key=lambda g: g.position_m)
            panels[(pre, "numerics (time from impact)")] = [
                (f"gauge bead {g.bead}", tt, g.average_force - g.average_force[0]) for g in gs] + [
                ("wall", tt, tr.wall_force - tr.wall_force[0])]
        yield FigureSpec("traces", f"traces_{mat.lower()}.png",
                         (f"{mat}: gauges (top two) and wall, gravity only vs 2.38 N", panels))
    fr = np.logspace(math.log10(1.06), 3, 40)
    pts = []
    for scene, style in (("ptfe52_gravity", "C0o"), ("ptfe52_magnetic", "C3o"),
                         ("steel21_gravity", "C0s"), ("steel21_magnetic", "C3s")):
        sw = results["sweeps"][scene]
        pts.append((f"virtual shots, {scene}", [p["truth_Fm"] / p["F0"] for p in sw], [p["truth_beta"] for p in sw],
                    style))
    yield FigureSpec("beta_curve", "beta.png", (fr, [beta_of(x) for x in fr], pts))
    for scene in ("ptfe52_gravity", "ptfe52_magnetic"):
        r = rigs[scene]
        tr = r.truth()
        low = sorted(tr.gauges.values(), key=lambda g: g.position_m)[-1]
        f = low.contact_below - low.static_below_N
        t = np.arange(f.size) * tr.sample_interval
        i = int(np.argmax(f[: int(0.6 * f.size)]))
        bead = r.chain.beads[-1]
        A = r.chain.contact_constants()[low.bead + 1]
        F0 = low.static_below_N
        wave = solitary_wave(bead.mass, A, bead.diameter, F0 + f[i], F0)
        j = int(np.argmax(wave.force))
        tw = -(wave.xi - wave.xi[j]) / wave.contacts_per_s
        window = np.abs(t - t[i]) < 4 * (tw.max() - tw.min()) / 10
        yield FigureSpec("pulse_vs_solitary", f"leading_pulse_vs_solitary_{scene}.png", (
            f"{scene}: leading pulse at contact {low.bead + 1}\\nvs the stationary solitary wave "
            f"of the same amplitude ({F0 + f[i]:.2f} N on F_0 = {F0:.3f} N)",
            [("virtual shot (numerics)", (t[window] - t[i]) * 1e6, f[window], "C0-"),
             ("exact discrete solitary wave", tw * 1e6, wave.force - F0, "k--")]))
