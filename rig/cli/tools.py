"""`rig theory` and `rig bench`."""
from __future__ import annotations

import math
import sys

from rig.cli.common import command, rounds_arg
from rig.errors import RigError, invalid
from rig.units import typed_quantity


def cmd_theory(args) -> dict:
    """The long-wave speeds, Eqs (2), (1), (4), and the exact discrete solitary wave's (in
    the long-wave theory's frame, contacts per second times the diameter, so that its ratio
    to Eq (4) depends on F_m/F_0 alone). A figure that cannot be computed is null, with its
    reason in "reasons" (and a line of the text output)."""
    from rig.model.contact import hertz_constant
    from rig.model.materials import material
    from rig.theory.longwave import solitary_wave_speed, sonic_vacuum_speed, sound_speed
    from rig.theory.solitary import MIN_FORCE_RATIO, overlap_reason, solitary_wave

    m = material(args.material)
    a = typed_quantity(args.diameter, "m", "--diameter")
    F0 = typed_quantity(args.f0, "N", "--f0")
    if not a > 0:
        raise RigError(f"--diameter = {args.diameter!r}: must be > 0 m")
    if not 0 <= F0 < math.inf:
        raise RigError(f"--f0 = {args.f0!r}: precompression must be >= 0 N")
    A = hertz_constant(m.E, m.nu, a / 2, m.E, m.nu, a / 2)
    out: dict = {"material": m.name, "diameter_m": a, "f0_N": F0, "fm_N": None, "sound_speed_m_per_s": None,
           "speed_m_per_s": None, "sonic_vacuum_speed_m_per_s": None, "discrete_speed_m_per_s": None,
           "discrete_lab_speed_m_per_s": None, "reasons": {}}
    reasons = out["reasons"]
    static = overlap_reason(A, a, F0)
    if static:
        reasons["sound_speed_m_per_s"] = f"--f0: {static}"
    else:
        out["sound_speed_m_per_s"] = float(sound_speed(m.E, m.nu, m.rho, a, F0))
    wave_keys = ("speed_m_per_s", "sonic_vacuum_speed_m_per_s", "discrete_speed_m_per_s",
                 "discrete_lab_speed_m_per_s")
    Fm = None if args.fm is None else typed_quantity(args.fm, "N", "--fm")
    dynamic = overlap_reason(A, a, Fm) if Fm is not None else None
    if Fm is None:
        reasons.update(dict.fromkeys(wave_keys, "no --fm (the wave's maximum force) given"))
    elif not F0 < Fm < math.inf:
        raise RigError(f"--fm = {args.fm!r}: the maximum force must exceed --f0 = {F0} N and be finite")
    elif dynamic:
        out["fm_N"] = Fm
        reasons.update(dict.fromkeys(wave_keys, f"--fm: {dynamic}"))
    else:
        out["fm_N"] = Fm
        out["sonic_vacuum_speed_m_per_s"] = float(sonic_vacuum_speed(m.E, m.nu, m.rho, a, Fm))
        out["speed_m_per_s"] = (float(solitary_wave_speed(m.E, m.nu, m.rho, a, F0, Fm)) if F0 > 0
                                else out["sonic_vacuum_speed_m_per_s"])
        if Fm >= MIN_FORCE_RATIO * F0:
            wave = solitary_wave(m.rho * math.pi * a**3 / 6, A, a, Fm, F0)
            out["discrete_speed_m_per_s"], out["discrete_lab_speed_m_per_s"] = wave.long_wave_speed, wave.speed
        else:
            reasons.update(dict.fromkeys(wave_keys[2:], (
                f"Fm/F0 = {Fm / F0:.4g} is below {MIN_FORCE_RATIO}: a wide, weakly nonlinear wave the discrete "
                "computation does not reach; Eq (1) describes it")))
    if args.yield_pressure is not None or args.yield_force is not None:
        out["yield_pressure_Pa"], out["yield_force_N"] = contact_yields(m, a, A, args)
    if not args.json:
        print(f"{m.name}, diameter {a * 1e3:g} mm, F0 = {F0:g} N" + (f", Fm = {Fm:g} N" if Fm is not None else ""))
        rows = [("sound speed c0, Eq (2)", "sound_speed_m_per_s"),
                ("solitary wave speed, Eq (1)", "speed_m_per_s"),
                ("sonic-vacuum speed, Eq (4)", "sonic_vacuum_speed_m_per_s"),
                ("exact discrete solitary wave", "discrete_speed_m_per_s"),
                ("  the same in the laboratory", "discrete_lab_speed_m_per_s")]
        for label, key in rows:
            v = out[key]
            print(f"  {label:30s} {'-' if v is None else f'{v:9.2f} m/s'}")
        for why in dict.fromkeys(reasons.values()):
            print(f"  -: {why}")
        if "yield_force_N" in out:
            print(f"  yield pressure p_y = {out['yield_pressure_Pa'] / 1e6:.4g} MPa: each contact yields at "
                  "F_y = pi^3 R*^2 p_y^3 / (6 E*^2)")
            for partner, f in out["yield_force_N"].items():
                print(f"    {partner:40s} {f:9.4g} N")
    return out


def contact_yields(m, a: float, A: float, args) -> tuple:
    """(p_y in Pa, {partner: F_y in N}) of a bead of material ``m`` and diameter ``a`` (m;
    A its bead-bead Hertz constant) against each partner the rig's parts give it: another
    such bead, the magnetic bead (chrome steel, 5 mm), the wall (brass, flat) and the
    striker's face (alumina, flat); --yield-force is the bead-bead force, read as the
    pressure that yields that contact (as chain.yield_force)."""
    from rig.model.contact import hertz_constant
    from rig.model.laws.thornton import pressure_yield_force, yield_pressure_of
    from rig.model.materials import material
    from rig.model.parts import MagneticBead

    if args.yield_pressure is not None and args.yield_force is not None:
        raise RigError(f"--yield-force = {args.yield_force!r}: give one of --yield-pressure or --yield-force")
    r = a / 2
    if args.yield_pressure is not None:
        p = typed_quantity(args.yield_pressure, "Pa", "--yield-pressure")
        if not 0 < p < math.inf:
            raise RigError(f"--yield-pressure = {args.yield_pressure!r}: a pressure > 0 Pa, e.g. '30 MPa'")
    else:
        F = typed_quantity(args.yield_force, "N", "--yield-force")
        if not 0 < F < math.inf:
            raise RigError(f"--yield-force = {args.yield_force!r}: a force > 0 N, e.g. '0.8 N'")
        p = float(yield_pressure_of(F, r / 2, A))
    steel, brass, alumina = material(MagneticBead().material), material("brass"), material("alumina")
    r_steel = MagneticBead().diameter / 2
    partners = {"another bead": (r / 2, A),
                "the magnetic bead (chrome steel, 5 mm)": (r * r_steel / (r + r_steel),
                                                           hertz_constant(m.E, m.nu, r, steel.E, steel.nu, r_steel)),
                "the wall (brass, flat)": (r, hertz_constant(m.E, m.nu, r, brass.E, brass.nu, math.inf)),
                "the striker's face (alumina, flat)": (r, hertz_constant(m.E, m.nu, r, alumina.E, alumina.nu,
                                                                         math.inf))}
    return p, {name: float(pressure_yield_force(p, R, k)) for name, (R, k) in partners.items()}


def cmd_bench(args) -> dict:
    import importlib

    module = importlib.import_module("rig.bench.cold_start" if args.what == "startup" and args.cold
                                     else f"rig.bench.{args.what}")
    if args.quick and args.what not in ("solver", "accuracy", "models", "fit"):
        raise RigError(f"--quick: only rig bench solver, accuracy, models and fit have a quick form (not {args.what})")
    if args.peers and args.what != "solver":
        raise RigError(f"--peers: only rig bench solver has peers (not {args.what})")
    if args.cold and args.what != "startup":
        raise RigError(f"--cold: only rig bench startup has a cold form (not {args.what})")
    cold = args.what == "startup" and args.cold
    if args.baseline and args.what not in ("solver", "mc") and not cold:
        raise RigError(f"--baseline {args.baseline}: only rig bench solver, rig bench mc and rig bench startup --cold "
                       f"measure a baseline")
    if args.rounds is not None and args.what not in ("solver", "mc") and not cold:
        raise invalid("--rounds", args.rounds, "only rig bench solver, rig bench mc and rig bench startup --cold "
                                               "take rounds")
    if args.baseline:
        from rig.bench.baseline import check_revision

        check_revision(args.baseline)
    kw = {}
    if args.what in ("solver", "accuracy", "models", "fit"):
        kw = {"quick": args.quick,
              "progress": None if args.json else (lambda msg: print(f"  running {msg}", file=sys.stderr, flush=True))}
    if args.what == "solver":
        kw.update(peers=args.peers, baseline=args.baseline, kernel_rounds=args.rounds)
    if (args.what == "mc" or cold) and args.baseline:
        kw["baseline"] = args.baseline
    if (args.what == "mc" or cold) and args.rounds is not None:
        kw["rounds"] = args.rounds
    result = module.run(**kw)
    if not args.json:
        if args.what == "solver":
            print(f"solver work-precision, {module.N_BEADS} steel beads, force error at contact "
                  f"{module.PROBE} (machine: {result['machine']})")
        print(module.table(result))
    return result


def add_theory(sub) -> None:
    """The parser of ``rig theory``."""
    th = command(sub, "theory", "long-wave and exact discrete solitary wave speeds", cmd_theory)
    th.add_argument("--material", default="ptfe", help="ptfe | steel316 | ... (default ptfe)")
    th.add_argument("--diameter", default="4.76 mm", help="bead diameter, e.g. 4.76mm (plain number: m)")
    th.add_argument("--f0", required=True, help="precompression F0 (plain number: N)")
    th.add_argument("--fm", help="maximum contact force Fm of the wave (plain number: N)")
    th.add_argument("--yield-pressure", help="a yield pressure (e.g. 30MPa; plain number: Pa): each contact's yield "
                                             "force, the bead's against its partners in the rig")
    th.add_argument("--yield-force", help="the bead-bead contacts' yield force (as chain.yield_force, e.g. 0.8N): "
                                          "the pressure it is and the other contacts' forces")


def add_bench(sub) -> None:
    """The parser of ``rig bench``."""
    be = command(sub, "bench", "benchmarks", cmd_bench)
    be.add_argument("what", choices=["solver", "accuracy", "models", "fit", "shot", "archive", "pipeline", "mc",
                                     "animate", "startup", "serve"],
                    help="what to benchmark")
    be.add_argument("--quick", action="store_true", help="solver, accuracy, models, fit: fewer settings, one repeat")
    be.add_argument("--peers", action="store_true",
                    help="solver: also scipy's DOP853, a numba-compiled DOP853 and LAMMPS (when installed)")
    be.add_argument("--cold", action="store_true",
                    help="startup: the first rig shot and rig mc with an empty numba cache (everything compiled), "
                         "beside the warm ones")
    be.add_argument("--baseline", metavar="REV",
                    help="solver, mc, startup --cold: measure git revision REV of this checkout too, "
                         "in turns with the current code")
    be.add_argument("--rounds", type=rounds_arg, metavar="N",
                    help="solver, mc, startup --cold: rounds, 1 to 100, "
                         "of the figures that run in turns with --baseline "
                         "(solver: its kernel figure only, default 3, 1 with --quick; mc: every figure, default 3; "
                         "startup --cold: default 1); more "
                         "rounds steady the ratios on a machine whose speed swings")

