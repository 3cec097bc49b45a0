"""`rig theory` and `rig bench`."""
from __future__ import annotations

import math
import sys

from rig.errors import RigError, invalid
from rig.units import typed_quantity


def cmd_theory(args) -> dict:
    from rig.model.contact import hertz_constant
    from rig.model.materials import material
    from rig.theory.longwave import solitary_wave_speed, sonic_vacuum_speed, sound_speed
    from rig.theory.solitary import MIN_FORCE_RATIO, solitary_wave

    m = material(args.material)
    a = typed_quantity(args.diameter, "m", "--diameter")
    F0 = typed_quantity(args.f0, "N", "--f0")
    if not a > 0:
        raise RigError(f"--diameter = {args.diameter!r}: must be > 0 m")
    if not 0 <= F0 < math.inf:
        raise RigError(f"--f0 = {args.f0!r}: precompression must be >= 0 N")
    out = {"material": m.name, "diameter_m": a, "f0_N": F0, "fm_N": None,
           "sound_speed_m_per_s": float(sound_speed(m.E, m.nu, m.rho, a, F0)),
           "speed_m_per_s": None, "sonic_vacuum_speed_m_per_s": None,
           "discrete_speed_m_per_s": None}
    if args.fm is not None:
        Fm = typed_quantity(args.fm, "N", "--fm")
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


def cmd_bench(args) -> dict:
    import importlib

    module = importlib.import_module(f"rig.bench.{args.what}")
    if args.quick and args.what not in ("solver", "accuracy", "models", "fit"):
        raise RigError(f"--quick: only rig bench solver, accuracy, models and fit have a quick form (not {args.what})")
    if args.peers and args.what != "solver":
        raise RigError(f"--peers: only rig bench solver has peers (not {args.what})")
    if args.baseline and args.what not in ("solver", "mc"):
        raise RigError(f"--baseline {args.baseline}: only rig bench solver and rig bench mc measure a baseline")
    if args.rounds is not None and args.what not in ("solver", "mc"):
        raise invalid("--rounds", args.rounds, "only rig bench solver and rig bench mc take rounds")
    if args.baseline:
        from rig.bench.baseline import check_revision

        check_revision(args.baseline)
    kw = {}
    if args.what in ("solver", "accuracy", "models", "fit"):
        kw = {"quick": args.quick,
              "progress": None if args.json else (lambda msg: print(f"  running {msg}", file=sys.stderr, flush=True))}
    if args.what == "solver":
        kw.update(peers=args.peers, baseline=args.baseline, kernel_rounds=args.rounds)
    if args.what == "mc" and args.baseline:
        kw["baseline"] = args.baseline
    if args.what == "mc" and args.rounds is not None:
        kw["rounds"] = args.rounds
    result = module.run(**kw)
    if not args.json:
        if args.what == "solver":
            print(f"solver work-precision, {module.N_BEADS} steel beads, force error at contact "
                  f"{module.PROBE} (machine: {result['machine']})")
        print(module.table(result))
    return result
