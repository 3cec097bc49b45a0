"""The ``rig`` command line. Every user mistake ends in one clear line, never a traceback."""
from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

from instruments.errors import InstrumentError

from .errors import RigError


def _q(text: str, unit: str, field: str) -> float:
    """A command-line quantity: a plain number is taken in ``unit``; else text with a unit."""
    from .units import quantity

    try:
        return float(text)
    except ValueError:
        return quantity(text, unit, field)


def cmd_theory(args) -> dict:
    from .contact import hertz_constant
    from .materials import material
    from .solitary import MIN_FORCE_RATIO, solitary_wave
    from .theory import solitary_wave_speed, sonic_vacuum_speed, sound_speed

    m = material(args.material)
    a = _q(args.diameter, "m", "--diameter")
    F0 = _q(args.f0, "N", "--f0")
    if not a > 0:
        raise RigError(f"--diameter = {args.diameter!r}: must be > 0 m")
    if not F0 >= 0:
        raise RigError(f"--f0 = {args.f0!r}: precompression must be >= 0 N")
    out = {"material": m.name, "diameter_m": a, "f0_N": F0, "fm_N": None,
           "sound_speed_m_per_s": float(sound_speed(m.E, m.nu, m.rho, a, F0)),
           "speed_m_per_s": None, "sonic_vacuum_speed_m_per_s": None,
           "discrete_speed_m_per_s": None}
    if args.fm is not None:
        Fm = _q(args.fm, "N", "--fm")
        if not Fm > F0:
            raise RigError(f"--fm = {args.fm!r}: the maximum force must exceed --f0 = {F0} N")
        out["fm_N"] = Fm
        out["sonic_vacuum_speed_m_per_s"] = float(sonic_vacuum_speed(m.E, m.nu, m.rho, a, Fm))
        out["speed_m_per_s"] = (float(solitary_wave_speed(m.E, m.nu, m.rho, a, F0, Fm)) if F0 > 0
                                else out["sonic_vacuum_speed_m_per_s"])
        if F0 == 0 or Fm >= MIN_FORCE_RATIO * F0:
            A = hertz_constant(m.E, m.nu, a / 2, m.E, m.nu, a / 2)
            mass = m.rho * math.pi * a**3 / 6
            out["discrete_speed_m_per_s"] = solitary_wave(mass, A, a, Fm, F0).speed
    if not args.json:
        print(f"{m.name}, diameter {a * 1e3:g} mm, F0 = {F0:g} N" + (f", Fm = {out['fm_N']:g} N" if args.fm else ""))
        rows = [("sound speed c0, Eq (2)", out["sound_speed_m_per_s"]),
                ("solitary wave speed, Eq (1)", out["speed_m_per_s"]),
                ("sonic-vacuum speed, Eq (4)", out["sonic_vacuum_speed_m_per_s"]),
                ("exact discrete solitary wave", out["discrete_speed_m_per_s"])]
        for label, v in rows:
            print(f"  {label:30s} {'-' if v is None else f'{v:9.2f} m/s'}")
    return out


def cmd_shot(args) -> dict:
    """Fire one virtual shot of a scene; print a summary or JSON; export scope files."""
    from pathlib import Path

    from instruments.formats import WRITERS

    from .shot import Rig

    from .measure import shot_blocks

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

        out["archived"] = {"archive": args.out, "shot": Archive(args.out).append([shot.to_entry()])[0]}
    if not args.json:
        print_shot(out)
    return out


def shot_summary(rig, shot) -> dict:
    """The JSON-ready summary of a shot (the keys of `rig shot --json`)."""
    st = shot.solver
    wiring = {ch: f"gauges.{n}" for n, (_, ch, _) in rig.gauges.items()}
    if rig.wall_sensor is not None:
        wiring[rig.wall_channel] = "wall_sensor"
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
    fmt = lambda v, scale=1.0, spec=".1f": "-" if v is None else format(v * scale, spec)  # noqa: E731
    print(f"  {'':10s} {'speed m/s':>10s} {'F_d N':>8s} {'F_m,e N':>8s} {'beta':>6s} {'pulses':>6s} {'FWHM us':>8s}")
    for label, r in (("truth", t), ("measured", m)):
        print(f"  {label:10s} {fmt(r['speed_m_per_s']):>10s} {fmt(r['amplitude_N'], 1, '.3f'):>8s} "
              f"{fmt(r['averaged_amplitude_N'], 1, '.3f'):>8s} {fmt(r['beta'], 1, '.3f'):>6s} "
              f"{fmt(r['pulses'], 1, '.0f'):>6s} {fmt(r['duration_s'], 1e6):>8s}")
    print(f"  theory     c0 = {fmt(th['sound_speed_m_per_s'])} m/s (Eq 2), "
          f"Eq (1) at the truth amplitude: {fmt(th['speed_m_per_s'])} m/s; "
          f"cross-correlation speed {fmt(m['speed_xcorr_m_per_s'])} m/s")
    for path in out.get("exported", []):
        print(f"  wrote {path}")
    if "archived" in out:
        print(f"  appended to {out['archived']['archive']} as shot {out['archived']['shot']}")


def cmd_verify(args) -> dict:
    from instruments.archive import Archive

    report = Archive(args.archive).verify()
    if not args.json:
        print(f"{args.archive}: {report['shots']} shots, {report['ok']} ok, {len(report['bad'])} bad")
        for b in report["bad"]:
            print(f"  shot {b['shot']}: {b['reason']}")
    args.exit_code = 1 if report["bad"] else 0
    return report


def cmd_import(args) -> dict:
    """Real scope files into an archive, in the same layout as virtual shots (simulated = false)."""
    from datetime import datetime, timezone
    from pathlib import Path

    from instruments.archive import Archive, Entry
    from instruments.formats import READERS
    from instruments.records import ScopeRecord

    groups = [args.files] if args.together else [[f] for f in args.files]
    entries = []
    for files in groups:
        waves = {}
        for name in files:
            path = Path(name)
            reader = READERS.get(path.suffix.lower())
            if reader is None:
                raise RigError(f"{path}: cannot import {path.suffix or 'extensionless'} files "
                               f"(known: {', '.join(READERS)})")
            for w in reader(path):
                key = w.channel if w.channel not in waves else f"{w.channel}@{path.stem}"
                waves[key] = w
        mtime = min(Path(f).stat().st_mtime for f in files)
        entries.append(Entry(ScopeRecord(waves, True), False, scene="",
                             settings={"source_files": [str(Path(f).resolve().name) for f in files]},
                             start_time=datetime.fromtimestamp(mtime, timezone.utc).isoformat()))
    ids = Archive(args.into).append(entries)
    out = {"archive": args.into, "shots": ids}
    if not args.json:
        print(f"imported {len(args.files)} file(s) into {args.into} as shot(s) {', '.join(map(str, ids))}")
    return out


def cmd_analyze(args) -> list:
    from .analyze import analyze_paths

    results = analyze_paths(args)
    if not args.json:
        fmt = lambda v, spec=".2f": "-" if v is None else format(v, spec)  # noqa: E731
        print(f"{'source':40s} {'V_s m/s':>8s} {'xcorr':>8s} {'F_d N':>8s} {'F_m,e N':>8s} "
              f"{'pulses':>6s} {'FWHM us':>8s} {'Eq1 m/s':>8s}")
        for r in results:
            fwhm = None if r["duration_s"] is None else r["duration_s"] * 1e6
            print(f"{r['source'][-40:]:40s} {fmt(r['speed_m_per_s'], '.1f'):>8s} "
                  f"{fmt(r['speed_xcorr_m_per_s'], '.1f'):>8s} {fmt(r['amplitude_N'], '.3f'):>8s} "
                  f"{fmt(r['averaged_amplitude_N'], '.3f'):>8s} {fmt(r['pulses'], '.0f'):>6s} "
                  f"{fmt(fwhm, '.1f'):>8s} {fmt(r['theory_speed_m_per_s'], '.1f'):>8s}")
    return results


def cmd_sweep(args) -> dict:
    from tqdm import tqdm

    from .shot import Rig
    from .sweep import Vary, run_sweep

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

    from .reproduce import CONFIGS, MASS_RATIOS, OTHER_SCENES, VELOCITY_FACTORS, reproduce

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

    from .distributions import parse_vary
    from .executors import run_study
    from .mc import Store, Study, _base
    from .mc_report import figures, jcgm101, sobol_indices
    from .theory import solitary_wave_speed

    dists = tuple(parse_vary(args.vary or []))
    shots = args.shots
    if args.sobol:
        from .mc import sobol_shots

        shots = sobol_shots(args.shots, len(dists))
        if shots != args.shots and not args.json:
            print(f"Sobol design over {len(dists)} inputs: {shots} shots "
                  f"({shots // (len(dists) + 2)} x {len(dists) + 2})", file=sys.stderr)
    study = Study(args.scene, dists, shots, args.seed, tuple(args.set or ()), args.batch, args.accuracy,
                  args.sobol)
    if not study.dists:
        raise RigError("--vary: give at least one uncertain input, e.g. striker.velocity=\"normal(0.89 m/s, 0.01 m/s)\"")
    _, _, base = _base(study.scene, study.overrides)  # the scene must be valid before any shot
    for d in study.dists:
        parts = d.key.split(".")
        if parts[0] == "gauges" and parts[1] not in base.gauges:
            raise RigError(f"--vary {d.key}: the scene has no gauge {parts[1]!r} (gauges: {', '.join(base.gauges)})")
    if study.sobol:
        from .mc import sobol_matrix

        sobol_matrix(study)
    store = Store(args.out, study).open()
    done = sum(min(study.shots, (b + 1) * study.batch) - b * study.batch for b in store.done())
    t0 = time.perf_counter()
    with tqdm(total=study.shots, initial=done, desc="mc", unit="shot", file=sys.stderr,
              disable=args.quiet) as bar:
        try:
            run_study(study, store, args.workers, args.scheduler, bar.update)
        except KeyboardInterrupt:
            kept = sum(min(study.shots, (b + 1) * study.batch) - b * study.batch for b in store.done())
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
    from .measure import midway_static_force

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


def cmd_ls(args) -> list:
    from instruments.archive import Archive

    rows = Archive(args.archive).summary()
    if not args.json:
        print(f"{'shot':>5s}  {'start (UTC)':19s}  {'kind':7s}  {'scene':22s}  {'seed':>20s}  channels")
        for r in rows:
            s = r["settings"]
            extra = f"  v={s['velocity']:g} m/s" if "velocity" in s else ""
            what = r["scene"] or ",".join(r["sources"]) or "-"
            print(f"{r['shot']:5d}  {r['start_time'][:19]:19s}  {'virtual' if r['simulated'] else 'real':7s}  "
                  f"{what:22s}  {'' if r['seed'] is None else r['seed']:>20}  "
                  f"{','.join(r['channels'])}{'' if r['triggered'] else '  NO TRIGGER'}{extra}")
    return rows


def cmd_bench(args) -> dict:
    if args.what in ("shot", "archive", "pipeline", "mc"):
        import importlib

        module = importlib.import_module(f"benchmarks.{args.what}")
        result = module.run()
        if not args.json:
            print(module.table(result))
        return result
    from benchmarks import solver as bench

    progress = None if args.json else (lambda msg: print(f"  running {msg}", file=sys.stderr, flush=True))
    result = bench.run(quick=args.quick, progress=progress)
    if not args.json:
        print(f"solver work-precision, {bench.N_BEADS} steel beads, force error at contact "
              f"{bench.PROBE} (machine: {result['machine']})")
        print(bench.table(result))
    return result


def build_parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(prog="rig", description="Virtual rig for strongly nonlinear granular chains.")
    sub = ap.add_subparsers(dest="command", required=True)

    th = sub.add_parser("theory", help="long-wave and exact discrete solitary wave speeds")
    th.add_argument("--material", default="ptfe", help="ptfe | steel316 | ... (default ptfe)")
    th.add_argument("--diameter", default="4.76 mm", help="bead diameter, e.g. 4.76mm (plain number: m)")
    th.add_argument("--f0", required=True, help="precompression F0 (plain number: N)")
    th.add_argument("--fm", help="maximum contact force Fm of the wave (plain number: N)")
    th.add_argument("--json", action="store_true", help="print JSON")
    th.set_defaults(func=cmd_theory)

    sh = sub.add_parser("shot", help="fire one virtual shot of a scene")
    sh.add_argument("scene", help="a scene file, or a published scene's name (e.g. ptfe52_magnetic)")
    sh.add_argument("--set", action="append", metavar="KEY=VALUE",
                    help="override a scene key, e.g. striker.velocity=1.2 (plain numbers in SI)")
    sh.add_argument("--seed", type=int, help="seed of every random draw (default: a fresh one, printed)")
    sh.add_argument("--export", metavar="DIR", help="write the scope records to DIR")
    sh.add_argument("--format", choices=["isf", "csv"], default="isf", help="scope file format (default isf)")
    sh.add_argument("--out", metavar="ARCHIVE.h5", help="append the shot to an HDF5 archive")
    sh.add_argument("--json", action="store_true", help="print JSON")
    sh.set_defaults(func=cmd_shot)

    ve = sub.add_parser("verify", help="check every shot of an archive (exit 1 if any is bad)")
    ve.add_argument("archive")
    ve.add_argument("--json", action="store_true", help="print JSON")
    ve.set_defaults(func=cmd_verify)

    im = sub.add_parser("import", help="import real scope files into an archive")
    im.add_argument("files", nargs="+", metavar="FILE")
    im.add_argument("--into", required=True, metavar="ARCHIVE.h5")
    im.add_argument("--together", action="store_true", help="the files are the channels of one shot")
    im.add_argument("--json", action="store_true", help="print JSON")
    im.set_defaults(func=cmd_import)

    sw = sub.add_parser("sweep", help="one shot per value of a scene key")
    sw.add_argument("scene")
    sw.add_argument("--vary", required=True, metavar="KEY=START:STOP:COUNT",
                    help="e.g. striker.velocity=0.3:1.5:7 (plain numbers in the key's SI unit)")
    sw.add_argument("--set", action="append", metavar="KEY=VALUE", help="other overrides")
    sw.add_argument("--seed", type=int, default=0, help="the sweep's seed (default 0)")
    sw.add_argument("--out", metavar="ARCHIVE.h5", help="append every shot to an archive")
    sw.add_argument("--quiet", action="store_true", help="no progress bar")
    sw.add_argument("--json", action="store_true", help="print JSON")
    sw.set_defaults(func=cmd_sweep)

    rp = sub.add_parser("reproduce", help="re-run a published study (daraio2006)")
    rp.add_argument("study", help="daraio2006")
    rp.add_argument("--out", required=True, metavar="DIR", help="folder for tables and figures")
    rp.add_argument("--quiet", action="store_true", help="no progress bar")
    rp.add_argument("--json", action="store_true", help="print JSON")
    rp.set_defaults(func=cmd_reproduce)

    mc = sub.add_parser("mc", help="Monte Carlo study over many virtual shots")
    mc.add_argument("scene")
    mc.add_argument("--shots", type=int, required=True)
    mc.add_argument("--vary", action="append", metavar="KEY=DIST",
                    help='e.g. striker.velocity="normal(0.89 m/s, 0.01 m/s)"; also chain.bead_mass, '
                         'gauges.NAME.gain, gauges.NAME.misalignment')
    mc.add_argument("--set", action="append", metavar="KEY=VALUE", help="fixed overrides")
    mc.add_argument("--seed", type=int, default=0, help="the study's seed (default 0)")
    mc.add_argument("--batch", type=int, default=128, help="shots per batch (default 128)")
    mc.add_argument("--accuracy", type=float, help="solver accuracy (default: the scene's)")
    mc.add_argument("--workers", type=int, default=1, help="local worker processes (default 1)")
    mc.add_argument("--scheduler", help="Dask scheduler: tcp://HOST:PORT, or 'local' for a LocalCluster")
    mc.add_argument("--sobol", action="store_true", help="Sobol design and indices (needs SALib)")
    mc.add_argument("--out", required=True, metavar="DIR")
    mc.add_argument("--quiet", action="store_true", help="no progress bar")
    mc.add_argument("--json", action="store_true", help="print JSON")
    mc.set_defaults(func=cmd_mc)

    an = sub.add_parser("analyze", help="speeds and amplitudes from scope files or an archive")
    an.add_argument("files", nargs="+", metavar="FILE", help=".isf, .csv or .h5 (an archive)")
    an.add_argument("--shot", type=int, help="one shot of an archive (default: every shot)")
    an.add_argument("--gauge-distance", type=lambda s: _q(s, "m", "--gauge-distance"),
                    help="distance between the two gauges (plain number: m), for real files")
    an.add_argument("--channels", help="UPPER,LOWER[,WALL] channel names (default: file order)")
    an.add_argument("--wall", action="store_true", help="the third channel is the wall sensor")
    an.add_argument("--sensitivity", type=float, default=1.0, help="gauge sensitivity V/N (default 1: volts)")
    an.add_argument("--tau", type=lambda s: _q(s, "s", "--tau"), help="gauge RC time constant to invert (s)")
    an.add_argument("--beta", type=float, default=1.0, help="beta = F_d / F_m,e (default 1)")
    an.add_argument("--f0", type=lambda s: _q(s, "N", "--f0"), default=0.0, help="precompression F_0 (N)")
    an.add_argument("--diameter", type=lambda s: _q(s, "m", "--diameter"), default=4.76e-3,
                    help="bead diameter (plain number: m; default 4.76 mm)")
    an.add_argument("--material", help="bead material, to add the Eq (1) speed")
    an.add_argument("--json", action="store_true", help="print JSON")
    an.set_defaults(func=cmd_analyze)

    ls = sub.add_parser("ls", help="list the shots of an archive")
    ls.add_argument("archive")
    ls.add_argument("--json", action="store_true", help="print JSON")
    ls.set_defaults(func=cmd_ls)

    be = sub.add_parser("bench", help="benchmarks")
    be.add_argument("what", choices=["solver", "shot", "archive", "pipeline", "mc"], help="what to benchmark")
    be.add_argument("--quick", action="store_true", help="fewer settings, one repeat")
    be.add_argument("--json", action="store_true", help="print JSON")
    be.set_defaults(func=cmd_bench)
    return ap


def main(argv=None) -> int:
    args = build_parser().parse_args(argv)
    try:
        out = args.func(args)
    except (RigError, InstrumentError) as exc:
        print(f"rig {args.command}: error: {exc}", file=sys.stderr)
        return 2
    if args.json:
        print(json.dumps(out, indent=2))
    return getattr(args, "exit_code", 0)


if __name__ == "__main__":
    sys.exit(main())
