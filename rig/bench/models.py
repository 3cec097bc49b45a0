"""What each optional chain model costs, on and off (``rig bench models``; also a section
of ``rig bench solver``).

The published ``ptfe52_gravity`` scene with each model switched on by its scene keys:

- per step: the whole srkn6b step (elastic kicks and drifts, plus the model's split
  dissipation) in ns per bead per force evaluation on the same scene lengthened to 1000
  beads, at one fixed step for every model, measured in interleaved rounds with plain
  Hertz; the ratio is the model's price per step. The elastic-plastic law twice: at 5 N no
  contact of that chain yields (the law's own price); at 0.8 N the lower third of the long
  chain rests flattened by its weight at its elastic limit, and the beads' jitter makes
  those contacts yield at nearly every step: its worst case;
- at the accuracy contract (1e-4, the scene's 52 beads, 1 ms): the step the control
  picks, the CPU time, its ratio to Hertz, the estimate, and the share of the impact
  energy the model dissipated. A stiffer or faster law asks for a shorter step, so the
  controlled cost is what a user pays;
- off: each model's keys given at their "off" values (n = 3/2, no drag, no friction, the
  gauge bead at its default mass) must give Hertz's forces bit for bit, at Hertz's cost
  per step (the same code path). A viscous law is off when it is not named (a named one
  with zero damping is refused as a mistake); its kernel at zero damping is the
  conservative one (tests/solver/test_models.py).
"""
from __future__ import annotations

import statistics
import time

import numpy as np

from rig.bench.kernel_cost import in_motion
from rig.experiment.shot import Rig
from rig.solver.problem import ChainProblem
from rig.solver.solve import solve
from rig.solver.stepsize import contact_time_scale

SCENE = "ptfe52_gravity"
DURATION = 1e-3  # s
ACCURACY = 1e-4
LONG_BEADS = 1000
FIXED_STEPS = 2000
ON = {  # name: scene overrides switching the model on (values of the order a fit of PTFE finds)
    "hertz": [],
    "power law n=1.75": ["chain.contact_exponent=1.75"],
    "Kuwabara-Kono 2 us": ["chain.contact_law=kuwabara-kono", "chain.damping_time=2 us"],
    "dashpot 0.5 kg/s": ["chain.contact_law=dashpot", "chain.contact_damping=0.5 kg/s"],
    "Thornton yield 5 N": ["chain.contact_law=thornton", "chain.yield_force=5 N"],
    "Thornton yield 0.8 N": ["chain.contact_law=thornton", "chain.yield_force=0.8 N"],
    "holder drag": ["holder.drag=0.05 kg/s"],
    "holder friction": ["holder.friction=2 mN"],
    "compliant wall": ["wall.plate_mass=2 g", "wall.rod_stiffness=1e8 N/m"],
    "gauge mass": ["gauges.upper.mass=0.2 g", "gauges.lower.mass=0.2 g"],
}
ON["all together"] = [o for name in ("power law n=1.75", "dashpot 0.5 kg/s", "holder drag", "holder friction",
                                     "compliant wall") for o in ON[name]]
OFF = {  # name: the same keys at values that switch the model off
    "power law n=1.5": ["chain.contact_exponent=1.5"],
    "holder drag 0": ["holder.drag=0 kg/s"],
    "holder friction 0": ["holder.friction=0 N"],
    "gauge mass = default": ["gauges.upper.mass=0.116 g", "gauges.lower.mass=0.116 g"],
}


def _rig(overrides, beads=None) -> Rig:
    more = [f"chain.beads={beads}", f"holder.length={beads * 5} mm"] if beads else []
    return Rig.from_scene(SCENE, [f"solver.duration={DURATION * 1e3:g} ms", *more, *overrides])


def _per_step(cases: dict, rounds: int, progress) -> dict:
    """ns per bead per force evaluation of each case at one fixed step (Hertz's tau / 8)
    on the 1000-bead chain, every bead moving (kernel_cost.in_motion: the per-step cost of
    every body, whether or not the model lets the solver leave the beads at rest ahead of
    the pulse); medians over interleaved rounds, and each round's ratio to Hertz."""
    setups = {}
    for name, ov in cases.items():
        r = _rig(ov, LONG_BEADS)
        p = in_motion(ChainProblem.from_chain(r.chain))
        setups[name] = (p, r.save_at(contacts=False, averages=True))
    dt = contact_time_scale(setups["hertz"][0]) / 8
    for p, save in setups.values():  # compile outside the clock
        solve(p, 2 * dt, save=save, dt=dt, estimate=False)
    ns: dict[str, list] = {name: [] for name in cases}
    for k in range(rounds):
        if progress:
            progress(f"models per step, round {k + 1} of {rounds}")
        for name, (p, save) in setups.items():
            t0 = time.process_time()
            s = solve(p, FIXED_STEPS * dt, save=save, dt=dt, estimate=False)
            ns[name].append((time.process_time() - t0) / (s.stats.force_evaluations * p.moving_bodies) * 1e9)
    return {name: dict(ns=statistics.median(v), ratio=statistics.median(a / b for a, b in zip(v, ns["hertz"])))
            for name, v in ns.items()} | {"_dt_s": dt}


def _controlled(cases: dict, repeats: int, progress) -> dict:
    """Each case at the accuracy contract on the 52-bead scene: step, CPU (median), ratio to
    Hertz, the a-posteriori estimate, the dissipated share of the impact energy, and the
    recorded forces (for the bit comparison of the off rows)."""
    out: dict[str, dict] = {}
    for name, ov in cases.items():
        if progress:
            progress(f"models at accuracy {ACCURACY:g}: {name}")
        r = _rig(ov)
        p = ChainProblem.from_chain(r.chain)
        save = r.save_at(contacts=False, averages=True)
        sol = solve(p, DURATION, save=save, accuracy=ACCURACY)
        times = []
        for _ in range(repeats):
            t0 = time.process_time()
            solve(p, DURATION, save=save, accuracy=ACCURACY)
            times.append(time.process_time() - t0)
        impact = 0.5 * r.striker.mass * r.striker.velocity ** 2
        out[name] = dict(dt_s=sol.stats.dt_s, cpu_s=statistics.median(times), estimate=sol.stats.error_estimate,
                         dissipated_share=sol.stats.dissipated_energy_J / impact, forces=sol.forces)
    base = out["hertz"]["cpu_s"]
    for row in out.values():
        row["ratio"] = row["cpu_s"] / base
    return out


def run(quick: bool = False, progress=None) -> dict:
    cases = ON | OFF
    per_step = _per_step(cases, 1 if quick else 5, progress)
    dt = per_step.pop("_dt_s")
    controlled = _controlled(cases, 1 if quick else 5, progress)
    hertz = controlled["hertz"]["forces"]
    rows = []
    for name in cases:
        c = controlled[name]
        forces = c.pop("forces")
        same = None
        if name in OFF:
            same = all(np.array_equal(forces[k], hertz[k]) for k in hertz)
        rows.append(dict(model=name, off=name in OFF, overrides=cases[name], ns_per_bead_eval=per_step[name]["ns"],
                         ns_ratio_to_hertz=per_step[name]["ratio"], same_bits_as_hertz=same, **c))
    return dict(scene=SCENE, beads_per_step_figure=LONG_BEADS, fixed_dt_s=dt, accuracy=ACCURACY,
                duration_s=DURATION, rows=rows)


def table(r: dict) -> str:
    head = (f"{'model':22s} {'ns/bead/eval':>12s} {'x Hertz':>8s} | {'dt ns':>7s} {'CPU ms':>8s} {'x Hertz':>8s} "
            f"{'estimate':>9s} {'dissipated':>10s}  off: same bits")
    lines = [f"Optional models on {r['scene']}: per step at dt = {r['fixed_dt_s'] * 1e9:.1f} ns on "
             f"{r['beads_per_step_figure']} beads (CPU medians of interleaved rounds) | at accuracy "
             f"{r['accuracy']:g}, {r['duration_s'] * 1e3:g} ms, the scene's beads", head, "-" * len(head)]
    for x in r["rows"]:
        same = "" if x["same_bits_as_hertz"] is None else ("yes" if x["same_bits_as_hertz"] else "NO")
        lines.append(f"{x['model']:22s} {x['ns_per_bead_eval']:12.2f} {x['ns_ratio_to_hertz']:8.2f} | "
                     f"{x['dt_s'] * 1e9:7.0f} {x['cpu_s'] * 1e3:8.2f} {x['ratio']:8.2f} {x['estimate']:9.1e} "
                     f"{x['dissipated_share']:10.1%}  {same}")
    return "\n".join(lines)
