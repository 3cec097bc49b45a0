"""The ``rig`` command line. Every user mistake ends in one clear line, never a traceback."""
from __future__ import annotations

import argparse
import json
import math
import sys

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


def cmd_demo(args) -> dict:
    """A virtual shot of the published PTFE chain, solver only (instruments come later)."""
    import numpy as np

    from . import Bead, Chain, MagneticBead, Record, Striker, Wall, solve
    from .theory import sound_speed

    v = _q(args.velocity, "m/s", "--velocity")
    F = _q(args.force, "N", "--force")
    beads = [MagneticBead()] + [Bead("ptfe", "4.76 mm", "0.1226 g")] * args.beads
    chain = Chain(beads, striker=Striker("alumina", "0.47 g", v), wall=Wall(), top_force=F)
    upper, lower = 20, 29  # published gauges: 20th and 29th PTFE beads from the top
    if lower > args.beads:
        raise RigError(f"--beads = {args.beads}: the demo's gauges sit in beads 20 and 29; use >= 29")
    rec = Record({"upper": chain.gauge_probe(upper), "lower": chain.gauge_probe(lower),
                  "wall": chain.wall_probe()})
    sol = solve(chain.problem(rec), args.t_end * 1e-3)
    x = chain.equilibrium_positions()
    t = sol.time

    def first_peak(y):  # leading pulse: first maximum above half the record's peak
        dyn = y - y[0]
        i = int(np.argmax(dyn > 0.5 * dyn.max()))
        while i + 1 < len(y) and y[i + 1] >= y[i]:
            i += 1
        return t[i], dyn[i]

    t1, f1 = first_peak(sol.forces["upper"])
    t2, f2 = first_peak(sol.forces["lower"])
    speed = (x[lower] - x[upper]) / (t2 - t1)
    F0 = chain.static_forces()[(upper + lower) // 2 + 1]
    m = beads[1].material
    out = {"beads": args.beads + 1, "striker_velocity_m_per_s": v, "magnet_force_N": F,
           "solver": sol.stats.as_dict(), "leading_pulse": {
               "speed_m_per_s": speed, "averaged_amplitude_N": 0.5 * (f1 + f2),
               "sound_speed_m_per_s": float(sound_speed(m.E, m.nu, m.rho, 4.76e-3, F0))},
           "wall_peak_N": float(sol.forces["wall"].max())}
    if not args.json:
        s = sol.stats
        print(f"PTFE chain: magnetic bead + {args.beads} beads, striker 0.47 g at {v:g} m/s, magnet {F:g} N")
        print(f"  solver {s.method}: dt = {s.dt_s * 1e9:.1f} ns, {s.steps} steps, {s.wall_s * 1e3:.1f} ms, "
              f"energy error {s.energy_error:.1e}, momentum error {s.momentum_error:.1e}")
        print(f"  leading pulse between gauges 20 and 29: {speed:.1f} m/s, averaged amplitude "
              f"{0.5 * (f1 + f2):.3f} N (sound speed c0 = {out['leading_pulse']['sound_speed_m_per_s']:.1f} m/s)")
        print(f"  wall force peak {out['wall_peak_N']:.3f} N")
    return out


def cmd_bench(args) -> dict:
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

    de = sub.add_parser("demo", help="a solver-only shot of the published PTFE chain")
    de.add_argument("--beads", type=int, default=52, help="PTFE beads under the magnetic bead (default 52)")
    de.add_argument("--velocity", default="0.89", help="striker velocity (plain number: m/s)")
    de.add_argument("--force", default="2.38", help="magnet force (plain number: N)")
    de.add_argument("--t-end", type=float, default=1.5, help="simulated time in ms (default 1.5)")
    de.add_argument("--json", action="store_true", help="print JSON")
    de.set_defaults(func=cmd_demo)

    be = sub.add_parser("bench", help="benchmarks")
    be.add_argument("what", choices=["solver"], help="what to benchmark")
    be.add_argument("--quick", action="store_true", help="fewer settings, one repeat")
    be.add_argument("--json", action="store_true", help="print JSON")
    be.set_defaults(func=cmd_bench)
    return ap


def main(argv=None) -> int:
    args = build_parser().parse_args(argv)
    try:
        out = args.func(args)
    except RigError as exc:
        print(f"rig {args.command}: error: {exc}", file=sys.stderr)
        return 2
    if args.json:
        print(json.dumps(out, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
