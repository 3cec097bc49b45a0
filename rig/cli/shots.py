"""`rig shot` and `rig animate`: one virtual shot, summarised, exported or rendered."""
from __future__ import annotations

from rig.cli.common import (
    allow_large,
    check_archive_out,
    check_export_folder,
    check_size,
    command,
    compiling_cold,
    flag_lines,
    missing_lines,
    plain,
    progress_bar,
    scene_overrides,
    seed_arg,
    writing_to,
)
from rig.errors import RigError, invalid


def cmd_shot(args) -> dict:
    """Fire one virtual shot of a scene; print a summary or JSON; export scope files."""
    from rig.experiment.scene import load

    if args.format is not None and not args.export:
        raise invalid("--format", args.format, "needs --export DIR (the format of the scope files it writes)")
    if args.export:
        check_export_folder(args.export, "--export")
    if args.out:
        check_archive_out(args.out, "--out")
    scene = load(args.scene, scene_overrides(args))  # a bad scene stops here, before numba is loaded
    from pathlib import Path

    from instruments.formats import WRITERS
    from rig.experiment.measure import shot_blocks
    from rig.experiment.shot import Rig

    if args.repeat is not None:
        if args.export:
            raise invalid("--export", args.export, "one shot's scope files; with --repeat archive the shots (--out)")
        return repeat_shots(args, scene)
    with compiling_cold("shot", "shot"):  # a refused shot leaves no side process
        rig = Rig(scene)
        check_size(rig.estimate(), args, "this shot")
    shot = rig.fire(seed=args.seed)
    out = shot_summary(rig, shot)
    out.update(shot_blocks(rig, shot))
    if args.export:
        if not shot.scope.waveforms:  # NORMal and no trigger (AUTO took an untriggered record)
            raise RigError(f"--export: nothing to export, the scope did not trigger ({shot.scope.reason})")
        from instruments.files import made_folder

        folder = Path(args.export)
        with writing_to(folder), made_folder(folder):  # a failed export leaves no folder it created
            paths = WRITERS[args.format or "isf"](shot.scope.waveforms, folder, f"{shot.scene}_seed{shot.seed}")
        out["exported"] = [str(p) for p in paths]
    if args.out:
        out["archived"] = archived(args.out, shot)
    if not args.json:
        print_shot(out, "the striker's kinetic energy" if rig.chain.striker is not None else "the static energy")
    return out


def archived(path: str, shot) -> dict:
    """Append ``shot`` to the archive at ``path`` (rig.lab.shots.append_shot, as the served
    scope's --out does): {"archive", "shot": its number}; an I/O failure names the path."""
    from rig.lab.shots import append_shot

    with writing_to(path):
        return {"archive": path, "shot": append_shot(path, shot)}


def repeat_shots(args, scene) -> dict:
    """``rig shot --repeat N``: N shots on one chain (chain.previous_shots from the scene's
    on, seeds N0, N0 + 1, ...), each meeting the contacts the last one flattened; per shot
    the truth's speed and amplitude and the energy the contacts took, and their drift from
    the first shot to the last ({"repeat": [...], "drift": {...}})."""
    from rig.experiment.scene import load
    from rig.experiment.shot import Rig, fresh_seed

    seed = fresh_seed() if args.seed is None else args.seed
    with compiling_cold("shot", "shot"):
        first = Rig(scene)
        check_size(first.estimate(), args, "each shot")
    rows, rig = [], first
    for k in range(args.repeat):
        if k:
            items = tuple(o for o in scene.overrides if o.split("=", 1)[0].strip() != "chain.previous_shots")
            rig = Rig(load(args.scene, items + (f"chain.previous_shots={first.previous_shots + k}",)), after=rig)
        shot = rig.fire(seed=seed + k)
        truth = rig.truth_analysis().as_dict()
        rows.append({"shot": first.previous_shots + k + 1, "seed": seed + k, "overrides": list(shot.overrides),
                     "speed_m_per_s": truth.get("speed_m_per_s"),
                     "averaged_amplitude_N": truth.get("averaged_amplitude_N"),
                     "dissipated_energy_J": rig.solution().stats.dissipated_energy_J,
                     "triggered": shot.scope.triggered})
        if args.out:
            rows[-1]["archived"] = archived(args.out, shot)

    def drift(key):
        a, b = rows[0][key], rows[-1][key]
        return None if a is None or b is None else {"first": a, "last": b, "relative": b / a - 1.0 if a else None}

    out = {"scenario": scene.name, "repeat": rows,
           "drift": {key: drift(key) for key in ("speed_m_per_s", "averaged_amplitude_N", "dissipated_energy_J")}}
    if not args.json:
        print(f"{scene.name}: {args.repeat} shot{'s' if args.repeat > 1 else ''} on one chain (the truth, noise-free)")
        print(f"  {'shot':>4s} {'seed':>8s} {'speed m/s':>10s} {'F_m,e N':>8s} {'plastic+viscous J':>18s}")
        for r in rows:
            speed = "-" if r["speed_m_per_s"] is None else f"{r['speed_m_per_s']:.1f}"
            amp = "-" if r["averaged_amplitude_N"] is None else f"{r['averaged_amplitude_N']:.3f}"
            print(f"  {r['shot']:4d} {r['seed']:8d} {speed:>10s} {amp:>8s} {r['dissipated_energy_J']:18.3e}")
        for key, what in (("speed_m_per_s", "speed"), ("averaged_amplitude_N", "F_m,e"),
                          ("dissipated_energy_J", "energy the contacts took")):
            d = out["drift"][key]
            if len(rows) > 1 and d is not None and d["relative"] is not None:
                print(f"  {what} drift from shot {rows[0]['shot']} to {rows[-1]['shot']}: {d['relative']:+.1%}")
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
                       "momentum_error": st.momentum_error, "accuracy": st.accuracy,
                       "error_estimate": st.error_estimate, "bodies_stepped": st.bodies_stepped},
            "triggered": shot.scope.triggered, "no_trigger_reason": shot.scope.reason,
            "trigger": {"source": tr.source, "level_V": tr.level, "slope": tr.slope,
                        "time_after_impact_s": shot.scope.trigger_time},
            "channels": channels}


def print_shot(out: dict, energy: str):
    """The summary of `rig shot`; ``energy``: what the energy error is relative to."""
    s = out["solver"]
    print(f"{out['scenario']} (seed {out['seed']})")
    print(f"  solver {s['method']}: dt = {s['dt_s'] * 1e9:.1f} ns, {s['steps']} steps in "
          f"{s['wall_s'] * 1e3:.1f} ms, energy error {s['energy_error']:.1e} of {energy}, "
          f"momentum error {s['momentum_error']:.1e}")
    if s["error_estimate"] is not None:
        print(f"  force error (relative to each record's dynamic peak): estimated {s['error_estimate']:.1e}"
              + (f", accuracy asked {s['accuracy']:.0e}" if s["accuracy"] is not None else ""))
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
        print_blocks(t, m, th)
    for path in out.get("exported", []):
        print(f"  wrote {path}")
    if "archived" in out:
        print(f"  appended to {out['archived']['archive']} as shot {out['archived']['shot']}")


def print_blocks(t, m, th):
    """The truth / measured / theory rows of a shot's summary."""
    def fmt(v, scale=1.0, spec=".1f"):
        return "-" if v is None else format(v * scale, spec)
    print(f"  {'':10s} {'speed m/s':>10s} {'F_d N':>8s} {'F_m,e N':>8s} {'beta':>6s} {'pulses':>6s} {'FWHM us':>8s}")
    for label, r in (("truth", t), ("measured", m)):
        print(f"  {label:10s} {fmt(r['speed_m_per_s']):>10s} {fmt(r['amplitude_N'], 1, '.3f'):>8s} "
              f"{fmt(r['averaged_amplitude_N'], 1, '.3f'):>8s} {fmt(r['beta'], 1, '.3f'):>6s} "
              f"{fmt(r['pulses'], 1, '.0f'):>6s} {fmt(r['duration_s'], 1e6):>8s}")
    print(f"  theory     c0 = {fmt(th['sound_speed_m_per_s'])} m/s (Eq 2), "
          f"Eq (1) at the truth amplitude: {fmt(th['speed_m_per_s'])} m/s; "
          f"cross-correlation speed {fmt(m['speed_xcorr_m_per_s'])} m/s")
    for line in missing_lines(m.get("reasons", {})):
        print(f"  measured: {line}")
    for label, r in (("truth", t), ("measured", m)):
        for line in flag_lines(r.get("flags", {})):
            print(f"  {label}: {line}")


def cmd_animate(args) -> dict:
    """Render a virtual shot to a movie or a still, off-screen (pyvista)."""
    from rig.experiment.scene import load
    from rig.viz.animate import check_output, require_renderer
    from rig.viz.movie_cost import check_options, movie_estimate

    check_output(args.out)  # before anything is computed
    check_options(args.frames, args.exaggerate)
    scene = load(args.scene, scene_overrides(args))
    require_renderer(args.out)
    from rig.experiment.shot import Rig
    from rig.viz.animate import animate

    rig = Rig(scene)
    rig.check_record()  # the movie's traces are the shot's scope record
    check_size(movie_estimate(rig.estimate(), args.frames, args.out), args, "this movie")
    still = args.out.lower().endswith(".png")
    with progress_bar(args.quiet or still, total=None if still else args.frames, desc="animate",
                      unit="frame") as bar:
        out = animate(rig, args.out, frames=args.frames, exaggerate=args.exaggerate, seed=args.seed,
                      progress=bar.update)
    if not args.json:
        what = (f"a still at t = {out['still_time_s'] * 1e3:.3f} ms, the nearest of {out['instants']} instants "
                f"(--frames) to {out['still_at']}" if still else f"{out['frames']} frames")
        print(f"wrote {out['out']}: {what}, displacements x {out['exaggerate']:.3g}, "
              f"seed {out['seed']}, {out['seconds']:.1f} s")
    return out


def repeat_arg(text: str) -> int:
    """--repeat: a whole number of shots 1..100."""
    import argparse

    try:
        n = int(text)
    except ValueError:
        n = 0
    if not 1 <= n <= 100 or str(n) != text.strip():
        raise argparse.ArgumentTypeError(f"--repeat = {text!r}: a whole number of shots from 1 to 100")
    return n


def add_shot(sub) -> None:
    """The parser of ``rig shot``."""
    sh = command(sub, "shot", "fire one virtual shot of a scene", cmd_shot)
    sh.add_argument("scene", help="a scene file, or a published scene's name (e.g. ptfe52_magnetic)")
    sh.add_argument("--set", action="append", metavar="KEY=VALUE",
                    help="override a scene key, e.g. striker.velocity=1.2 (plain numbers in SI)")
    sh.add_argument("--seed", type=seed_arg, help="seed of every random draw (default: a fresh one, printed)")
    sh.add_argument("--export", metavar="DIR", help="write the scope records to DIR")
    sh.add_argument("--format", choices=["isf", "csv"], help="with --export: scope file format (default isf)")
    sh.add_argument("--out", metavar="ARCHIVE.h5", help="append the shot to an HDF5 archive")
    sh.add_argument("--repeat", type=repeat_arg, metavar="N",
                    help="fire N shots (1-100) on one chain: each meets the contacts the last flattened "
                         "(chain.previous_shots), seeds SEED, SEED+1, ...; prints the drift of speed and amplitude")
    allow_large(sh)


def add_animate(sub) -> None:
    """The parser of ``rig animate``."""
    an = command(sub, "animate", "render a virtual shot to a movie or still, off-screen", cmd_animate)
    an.add_argument("scene")
    an.add_argument("--set", action="append", metavar="KEY=VALUE", help="override a scene key")
    an.add_argument("--seed", type=seed_arg, help="seed of the instruments' draws (default: a fresh one, printed)")
    an.add_argument("--out", required=True, metavar="FILE", help="FILE.mp4, FILE.gif or FILE.png (one still)")
    an.add_argument("--frames", type=plain(int), default=100,
                    help="frames over the scene's duration (default 100); for a .png still, the instants "
                         "it is picked from (the one nearest the leading pulse at the last gauge)")
    an.add_argument("--exaggerate", type=plain(float),
                    help="displacement factor (default: the largest displacement shown as 1/3 diameter)")
    an.add_argument("--quiet", action="store_true", help="no progress bar")
    allow_large(an)
