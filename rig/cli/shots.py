"""`rig shot`, `rig sweep`, `rig reproduce` and `rig mc`."""
from __future__ import annotations

import json
import sys
from pathlib import Path

from rig.errors import RigError


def cmd_shot(args) -> dict:
    """Fire one virtual shot of a scene; print a summary or JSON; export scope files."""
    from pathlib import Path

    from instruments.formats import WRITERS

    from rig.experiment.shot import Rig

    from rig.experiment.measure import shot_blocks

    rig = Rig.from_scene(args.scene, args.set or ())
    shot = rig.fire(seed=args.seed)
    out = shot_summary(rig, shot)
    out.update(shot_blocks(rig, shot))
    if args.export:
        if not shot.scope.triggered:
            raise RigError(f"--export: nothing to export, the scope did not trigger ({shot.scope.reason})")
        folder = Path(args.export)
        folder.mkdir(parents=True, exist_ok=True)
        paths = WRITERS[args.format](shot.scope.waveforms, folder, f"{shot.scene}_seed{shot.seed}")
        out["exported"] = [str(p) for p in paths]
    if args.out:
        from instruments.archive import Archive

        from rig.experiment.entry import shot_entry

        out["archived"] = {"archive": args.out, "shot": Archive(args.out).append([shot_entry(shot)])[0]}
    if not args.json:
        print_shot(out)
    return out


def shot_summary(rig, shot) -> dict:
    """The JSON-ready summary of a shot (the keys of `rig shot --json`)."""
    st = shot.solver
    wiring = rig.wiring()
    tr = rig.scope.trigger
    channels = {}
    for ch, w in shot.scope.waveforms.items():
        v = w.volts()
        p = w.preamble
        channels[ch] = {"connected": wiring.get(ch), "samples": p.points,
                        "sample_interval_s": p.x_increment, "trigger_index": p.trigger_index,
                        "first_sample_s": p.x_zero, "volts_per_div": p.extra["volts_per_div"],
                        "y_multiplier_V": p.y_multiplier, "min_V": float(v.min()),
                        "max_V": float(v.max()), "clipped": w.overrange}
    return {"scenario": shot.scene, "seed": shot.seed, "overrides": list(shot.overrides),
            "solver": {"method": st.method, "dt_s": st.dt_s, "steps": st.steps,
                       "wall_s": st.wall_s, "energy_error": st.energy_error,
                       "momentum_error": st.momentum_error},
            "triggered": shot.scope.triggered, "no_trigger_reason": shot.scope.reason,
            "trigger": {"source": tr.source, "level_V": tr.level, "slope": tr.slope,
                        "time_after_impact_s": shot.scope.trigger_time},
            "channels": channels}


def print_shot(out: dict):
    s = out["solver"]
    print(f"{out['scenario']} (seed {out['seed']})")
    print(f"  solver {s['method']}: dt = {s['dt_s'] * 1e9:.1f} ns, {s['steps']} steps, "
          f"{s['wall_s'] * 1e3:.1f} ms, energy error {s['energy_error']:.1e}, "
          f"momentum error {s['momentum_error']:.1e}")
    tr = out["trigger"]
    if not out["triggered"]:
        print(f"  scope: NO TRIGGER ({out['no_trigger_reason']})")
        return
    print(f"  scope: triggered on {tr['source']} ({tr['slope']}, {tr['level_V'] * 1e3:g} mV) "
          f"{tr['time_after_impact_s'] * 1e3:.3f} ms after impact")
    for ch, c in out["channels"].items():
        print(f"  {ch} {c['connected'] or 'unconnected':14s} {c['samples']} samples at "
              f"{c['sample_interval_s'] * 1e6:g} us, trigger at sample {c['trigger_index']}, "
              f"{c['volts_per_div'] * 1e3:g} mV/div, {c['min_V']:+.3f} .. {c['max_V']:+.3f} V"
              f"{'  CLIPPED' if c['clipped'] else ''}")
    t, m, th = out["truth"], out["measured"], out["theory"]
    if t is None:
        print("  (speeds and amplitudes need two gauge beads)")
    else:
        _print_blocks(t, m, th)
    for path in out.get("exported", []):
        print(f"  wrote {path}")
    if "archived" in out:
        print(f"  appended to {out['archived']['archive']} as shot {out['archived']['shot']}")


def cmd_sweep(args) -> dict:
    from tqdm import tqdm

    from rig.experiment.shot import Rig
    from rig.study.sweep import Vary, run_sweep

    vary = Vary.parse(args.vary)
    Rig.from_scene(args.scene, args.set or ())  # the base scene itself must be valid
    with tqdm(total=len(vary.values), desc=f"sweep {vary.key}", unit="shot", file=sys.stderr,
              disable=args.quiet) as bar:
        points = run_sweep(args.scene, vary, args.set or (), args.seed, bar.update, args.out)
    out = {"points": []}
    for p in points:
        one = shot_summary(p.rig, p.shot)
        one.update(p.blocks)
        one["value"] = p.value
        out["points"].append(one)
    if not args.json:
        fmt = lambda v, spec: "-" if v is None else format(v, spec)  # noqa: E731
        print(f"{vary.key:>18s} | {'truth F_d N':>11s} {'V_s m/s':>8s} | {'measured F_d N':>14s} "
              f"{'V_s m/s':>8s} | {'Eq (1) m/s':>10s}")
        clipped = []
        for p in out["points"]:
            t, m = p["truth"], p["measured"]
            print(f"{p['value']:18.6g} | {fmt(t['amplitude_N'], '11.3f')} {fmt(t['speed_m_per_s'], '8.1f')} | "
                  f"{fmt(m['amplitude_N'], '14.3f')} {fmt(m['speed_m_per_s'], '8.1f')} | "
                  f"{fmt(p['theory']['speed_m_per_s'], '10.1f')}"
                  f"{'  CLIPPED: ' + ','.join(c) if (c := [k for k, v in p['channels'].items() if v['clipped']]) else ''}")
            clipped += [p["value"]] if any(v["clipped"] for v in p["channels"].values()) else []
        if clipped:
            print(f"clipped scope channels at {vary.key} = {', '.join(f'{v:g}' for v in clipped)}: "
                  f"those measurements read low; raise scope.channels.CHn.volts_per_div")
        if args.out:
            print(f"appended {len(points)} shots to {args.out}")
    return out


def cmd_reproduce(args) -> dict:
    from tqdm import tqdm

    from rig.study.reproduce import CONFIGS, MASS_RATIOS, OTHER_SCENES, VELOCITY_FACTORS, reproduce

    total = len(CONFIGS) + len(OTHER_SCENES) + len(CONFIGS) * len(VELOCITY_FACTORS) + len(MASS_RATIOS) + 1
    with tqdm(total=total, desc=f"reproduce {args.study}", unit="step", file=sys.stderr,
              disable=args.quiet) as bar:
        def progress(what):
            bar.set_postfix_str(what[:40])
            bar.update()

        results = reproduce(args.study, args.out, progress)
    if not args.json:
        print((Path(args.out) / "table1.md").read_text())
        print(f"wrote {args.out}/: table1.md, table1.csv, summary.md, results.json and the figures")
    return {"out": args.out, "table1": results["table1"], "summary": results["summary"]}


def cmd_mc(args) -> dict:
    import time

    import numpy as np
    from tqdm import tqdm

    from rig.study.distributions import parse_vary
    from rig.study.executors import run_study
    from rig.study.montecarlo import Store, Study, nominal_rig
    from rig.study.report import figures, jcgm101, sobol_indices
    from rig.theory.longwave import solitary_wave_speed

    dists = tuple(parse_vary(args.vary or []))
    shots = args.shots
    if args.sobol:
        from rig.study.montecarlo import sobol_shots

        shots = sobol_shots(args.shots, len(dists))
        if shots != args.shots and not args.json:
            print(f"Sobol design over {len(dists)} inputs: {shots} shots "
                  f"({shots // (len(dists) + 2)} x {len(dists) + 2})", file=sys.stderr)
    study = Study(args.scene, dists, shots, args.seed, tuple(args.set or ()), args.batch, args.accuracy,
                  args.sobol, args.truth, args.window, args.traces)
    if not study.dists:
        raise RigError("--vary: give at least one uncertain input, e.g. striker.velocity=\"normal(0.89 m/s, 0.01 m/s)\"")
    base = nominal_rig(study.scene, study.overrides)  # the scene must be valid before any shot
    for d in study.dists:
        parts = d.key.split(".")
        names = [g.name for g in base.gauges]
        if parts[0] == "gauges" and parts[1] not in names:
            raise RigError(f"--vary {d.key}: the scene has no gauge {parts[1]!r} (gauges: {', '.join(names)})")
    if study.sobol:
        from rig.study.montecarlo import sobol_matrix

        sobol_matrix(study)
    store = Store(args.out, study).open()
    done = sum(len(study.shots_of(b)) for b in store.done())
    t0 = time.perf_counter()
    with tqdm(total=study.shots, initial=done, desc="mc", unit="shot", file=sys.stderr,
              disable=args.quiet) as bar:
        try:
            run_study(study, store, args.workers, args.scheduler, bar.update)
        except KeyboardInterrupt:
            kept = sum(len(study.shots_of(b)) for b in store.done())
            raise RigError(f"interrupted: {kept} of {study.shots} shots are kept in {args.out}; "
                           f"run the same command again to resume") from None
    ran = study.shots - done
    elapsed = time.perf_counter() - t0
    results = store.collect()
    out = results["outputs"]
    report = {"shots": int(results["index"].size), "shots_per_s": ran / elapsed if ran else None,
              "speed_m_per_s": jcgm101(out["speed_m_per_s"]),
              "speed_xcorr_m_per_s": jcgm101(out["speed_xcorr_m_per_s"]),
              "amplitude_N": jcgm101(out["amplitude_N"]),
              "truth_speed_m_per_s": jcgm101(out["truth_speed_m_per_s"]),
              "truth_amplitude_N": jcgm101(out["truth_amplitude_N"]),
              "inputs": {d.key: d.text() for d in study.dists}}
    if study.sobol:
        report["sobol"] = {k: sobol_indices(study, results["inputs"], out[k]) for k in ("speed_m_per_s", "amplitude_N")}
    from rig.experiment.measure import midway_static_force

    F0 = midway_static_force(base)
    m = base.chain.beads[-1].material
    F = np.linspace(max(np.nanmin(out["amplitude_N"]) * 0.8, 1e-3), np.nanmax(out["amplitude_N"]) * 1.2, 100)
    figures(Path(args.out), results, study.keys,
            (F, solitary_wave_speed(m.E, m.nu, m.rho, base.chain.beads[-1].diameter, F0, F0 + F),
             f"Eq (1), F_0 = {F0:.3g} N"))
    store.consolidate(results, report)
    (Path(args.out) / "report.json").write_text(json.dumps(report, indent=1))
    if not args.json:
        print(f"{report['shots']} shots ({ran} run now"
              + (f", {report['shots_per_s']:.0f} shots/s" if ran else "") + f") in {args.out}")
        for key, label in (("speed_m_per_s", "speed V_s (m/s)"), ("amplitude_N", "amplitude F_d (N)")):
            r = report[key]
            if r["estimate"] is not None:
                print(f"  {label:20s} {r['estimate']:.4g} +- {r['std']:.3g}  95%: [{r['ci95'][0]:.4g}, "
                      f"{r['ci95'][1]:.4g}]  {'stable' if r['converged'] else 'not yet stable'} "
                      f"(JCGM 101, tolerance {r['tolerance']:.2g})")
        for key, s in report.get("sobol", {}).items():
            print(f"  Sobol {key} ({s['base_samples']} base samples): dominant input {s['dominant']}; total "
                  + ", ".join(f"{k} {v:.2f}+-{s['total_conf95'][k]:.2f}" for k, v in s["total"].items()))
        print("  wrote study.h5, report.json, histograms.png, speed_vs_amplitude.png")
    return report




def _print_blocks(t, m, th):
    """The truth / measured / theory rows of a shot's summary."""
    fmt = lambda v, scale=1.0, spec=".1f": "-" if v is None else format(v * scale, spec)  # noqa: E731
    print(f"  {'':10s} {'speed m/s':>10s} {'F_d N':>8s} {'F_m,e N':>8s} {'beta':>6s} {'pulses':>6s} {'FWHM us':>8s}")
    for label, r in (("truth", t), ("measured", m)):
        print(f"  {label:10s} {fmt(r['speed_m_per_s']):>10s} {fmt(r['amplitude_N'], 1, '.3f'):>8s} "
              f"{fmt(r['averaged_amplitude_N'], 1, '.3f'):>8s} {fmt(r['beta'], 1, '.3f'):>6s} "
              f"{fmt(r['pulses'], 1, '.0f'):>6s} {fmt(r['duration_s'], 1e6):>8s}")
    print(f"  theory     c0 = {fmt(th['sound_speed_m_per_s'])} m/s (Eq 2), "
          f"Eq (1) at the truth amplitude: {fmt(th['speed_m_per_s'])} m/s; "
          f"cross-correlation speed {fmt(m['speed_xcorr_m_per_s'])} m/s")


def cmd_animate(args) -> dict:
    """Render a virtual shot to a movie or a still, off-screen (pyvista)."""
    from tqdm import tqdm

    from rig.viz.animate import animate, check_output, require_renderer
    from rig.experiment.shot import Rig

    check_output(args.out)  # before anything is computed
    require_renderer()
    rig = Rig.from_scene(args.scene, args.set or ())
    still = args.out.lower().endswith(".png")
    with tqdm(total=None if still else args.frames, desc="animate", unit="frame", file=sys.stderr,
              disable=args.quiet or still) as bar:
        out = animate(rig, args.out, frames=args.frames, exaggerate=args.exaggerate, seed=args.seed,
                      progress=bar.update)
    if not args.json:
        print(f"wrote {out['out']}: {out['frames']} frame(s), displacements x {out['exaggerate']:.3g}, "
              f"seed {out['seed']}, {out['seconds']:.1f} s")
    return out
