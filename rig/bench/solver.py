"""Work-precision benchmark of the chain solver (``rig bench solver [--peers] [--baseline REV]``).

Two 1000-bead steel chains struck by one bead mass at 0.44 m/s: sonic vacuum (no gravity,
no precompression) and precompressed (2.38 N from the top, wall at the bottom). Every
solver records the same probe, the force of contact 500, on the same 1 MS/s grid. Error:
max |F - F_ref| / max |F_ref - F_ref(0)| against the converged reference of ``rig bench
accuracy``. CPU times are process times, medians of ROUNDS rounds in which every run of a
scenario takes its turn (the machine's drift over minutes falls on every method alike);
ratios at equal error are the medians of the per-round ratios.

- srkn6b and verlet at fixed outer steps tau / r (the head resolved), no estimate: the
  integrators' work-precision curves (ns/bead/eval per body a step integrated: the beads
  the pulse has not reached are left at rest, rig/solver/kernels/integrators.py; the peers
  integrate every body); srkn6b at the accuracy settings, the controlled
  solve with its estimate: what the contract costs;
- with ``--peers`` (rig/bench/peers.py): scipy's DOP853 and a numba-compiled DOP853 at
  several rtol, and LAMMPS at fixed steps when it is installed;
- at equal error: each method's CPU time interpolated (log-log) at 1e-4, 1e-5 and 1e-6,
  as a multiple of srkn6b's;
- the kernel: the whole srkn6b step in ns per bead per force evaluation at N = 1000 and
  N = 1e6, every bead moving, beside the machine's bounds (vectorised square roots; memory bandwidth) and,
  with ``--baseline REV``, the same figure of that revision measured in turns with it;
- the cost per simulated second from 1e3 to 1e6 beads at the step the accuracy control
  picks for 1e3, and its exponent;
- the optional chain models (rig/bench/models.py): each one's cost per step and at the
  accuracy contract beside plain Hertz, and its cost when off (none: the same bits).
"""
from __future__ import annotations

import math
import statistics

from rig.bench import models
from rig.bench.accuracy import cases, reference
from rig.bench.baseline import machine
from rig.bench.kernel_cost import kernel_figures, median_cpu, scaling
from rig.bench.problems import N_BEADS, PROBE, SCENARIOS, chain
from rig.solver.solution import relative_error
from rig.solver.solve import solve
from rig.solver.stepsize import contact_time_scale, head_contacts, stepping_at

DIVISIONS = {"srkn6b": (2, 3, 4, 6, 8, 12, 16, 24, 32), "verlet": (8, 16, 32, 64, 128, 256)}
SETTINGS = (1e-3, 1e-4, 1e-5, 1e-6)
PEERS = {"scipy-DOP853": (1e-6, 1e-8, 1e-10), "numba-DOP853": (1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12),
         "LAMMPS": (20, 50, 100)}  # rtol, or tau / dt for LAMMPS
EQUAL_ERRORS = (1e-4, 1e-5, 1e-6)
ROUNDS = 5  # every run of the work-precision curves, in turns with the others (interleaved)
QUICK = dict(divisions={"srkn6b": (3, 6, 12), "verlet": (32, 128)}, settings=(1e-4,), peers={
    "scipy-DOP853": (1e-8,), "numba-DOP853": (1e-8, 1e-10), "LAMMPS": (20,)}, scenarios=("precompressed",))

def _row(scenario, method, setting, cpu, error, evaluations, bodies, **extra) -> dict:
    return dict(scenario=scenario, method=method, setting=setting, cpu_s=cpu, error=error,
                ns_per_bead_eval=cpu / (evaluations * bodies) * 1e9 if evaluations else None, **extra)


def _ours(name, p, save, t_end, ref, divisions, settings) -> list:
    """The runs of srkn6b and verlet on one scenario, each a function giving its row: fixed
    outer steps tau / r without estimate, and the controlled solve at each accuracy setting."""
    tau = contact_time_scale(p, head_contacts(p) + 1)

    def fixed(method, r):
        def go():
            sol, cpu = median_cpu(lambda: solve(p, t_end, save=save, method=method, dt=stepping_at(p, tau / r),
                                                estimate=False), 1)
            return _row(name, method, f"dt=tau/{r}", cpu, relative_error(sol.forces, ref),
                        sol.stats.force_evaluations, sol.stats.bodies_stepped, dt_s=sol.stats.dt_s,
                        bodies_stepped=sol.stats.bodies_stepped)
        return f"{name}: {method} dt = tau/{r}", go

    def controlled(acc):
        def go():
            sol, cpu = median_cpu(lambda: solve(p, t_end, save=save, accuracy=acc), 1)
            return _row(name, "srkn6b-controlled", f"accuracy={acc:g}", cpu, relative_error(sol.forces, ref), None,
                        p.moving_bodies, dt_s=sol.stats.dt_s, estimate=sol.stats.error_estimate,
                        attempts=sol.stats.attempts)
        return f"{name}: srkn6b accuracy={acc:g} (controlled, with its estimate)", go

    return ([fixed(method, r) for method, rs in divisions.items() for r in rs]
            + [controlled(acc) for acc in settings])


def _peers(name, p, save, t_end, ref, peers) -> tuple:
    """(the runs of the peers on one scenario, each a function giving its row; notes)."""
    from rig.bench import lammps
    from rig.bench.peers import numba_dop853, scipy_dop853

    def peer(label, integrate, setting):
        def go():
            run = integrate(p, save, t_end, setting)
            return _row(name, run.name, run.setting, run.cpu_s, relative_error({"c": run.force}, {"c": ref["c500"]}),
                        run.rhs_evaluations, p.moving_bodies, **({"note": run.note} if label == "LAMMPS" else {}))
        return f"{name}: {label} {'dt = tau/' if label == 'LAMMPS' else 'rtol='}{setting:g}", go

    runs = [peer(label, integrate, rtol) for label, integrate in (("scipy-DOP853", scipy_dop853),
                                                                 ("numba-DOP853", numba_dop853))
            for rtol in peers[label]]
    if lammps.executable() is None:
        return runs, ["LAMMPS not installed (apt-get install lammps): skipped"]
    tau = contact_time_scale(p, head_contacts(p) + 1)
    return runs + [peer("LAMMPS", lambda p_, s_, t_, r: lammps.lammps_hertz(p_, s_, t_, tau / r), r)
                   for r in peers["LAMMPS"]], []


def interleaved(runs: list, rounds: int, progress=None) -> list:
    """Rows of every run, ``rounds`` times, each round running them all in turn, every other
    round in reverse order (so that the machine's drift over minutes, even within a round,
    falls on every method alike): a list per round, in the order of ``runs``."""
    out = []
    for k in range(rounds):
        order = range(len(runs)) if k % 2 == 0 else range(len(runs) - 1, -1, -1)
        rows = [None] * len(runs)
        for i in order:
            label, go = runs[i]
            if progress:
                progress(f"{label} (round {k + 1} of {rounds})")
            rows[i] = go()
        out.append(rows)
    return out


def median_rows(per_round: list) -> list:
    """One row per run: the first round's (errors are the same every round) with the median
    CPU time over the rounds (and ns per bead per evaluation from it)."""
    out = []
    for rows in zip(*per_round):
        row = dict(rows[0])
        cpu = statistics.median(r["cpu_s"] for r in rows)
        if row["ns_per_bead_eval"]:
            row["ns_per_bead_eval"] *= cpu / row["cpu_s"]
        row.update(cpu_s=cpu, cpu_rounds_s=[r["cpu_s"] for r in rows])
        out.append(row)
    return out


def equal_error_rounds(per_round: list) -> list:
    """at_equal_error within each round, then, per scenario, method and error, the median
    CPU and the median of the per-round ratios to srkn6b."""
    tables = [at_equal_error(rows) for rows in per_round]
    out = []
    for entries in zip(*tables):
        cpus = [e["cpu_s"] for e in entries if e["cpu_s"] is not None]
        ratios = [e["ratio_to_srkn6b"] for e in entries if e["ratio_to_srkn6b"] is not None]
        out.append(dict(entries[0], cpu_s=statistics.median(cpus) if cpus else None,
                        ratio_to_srkn6b=statistics.median(ratios) if ratios else None, rounds=len(ratios)))
    return out


def at_equal_error(rows: list, errors=EQUAL_ERRORS) -> list:
    """Per scenario, method and error level: the CPU time the method needs for that error,
    interpolated log-log between the two runs around it (None where its runs do not reach
    it), and that time over srkn6b's at fixed steps."""
    out = []
    for name in dict.fromkeys(r["scenario"] for r in rows):
        curves: dict = {}
        for r in rows:
            if r["scenario"] == name and r["error"] > 0:
                curves.setdefault(r["method"], []).append((r["error"], r["cpu_s"]))
        cost = {m: {e: _interpolate(pts, e) for e in errors} for m, pts in curves.items()}
        for m in curves:
            for e in errors:
                ours = cost.get("srkn6b", {}).get(e)
                mine = cost[m][e]
                out.append(dict(scenario=name, method=m, error=e, cpu_s=mine,
                                ratio_to_srkn6b=mine / ours if mine and ours else None))
    return out


def _interpolate(points, e):
    """CPU at error e on the (error, cpu) curve, log-log, between the nearest runs below and above it."""
    pts = sorted(points)
    below = [p for p in pts if p[0] <= e]
    above = [p for p in pts if p[0] >= e]
    if not below or not above:
        return None
    (e0, c0), (e1, c1) = max(below), min(above)
    if e0 == e1:
        return min(c0, c1)
    w = math.log(e / e0) / math.log(e1 / e0)
    return math.exp(math.log(c0) + w * (math.log(c1) - math.log(c0)))


def run(quick: bool = False, peers: bool = False, baseline: str | None = None, progress=None,
        kernel_rounds: int | None = None) -> dict:
    """The work-precision rows and their equal-error table, the kernel figure (with
    ``baseline`` in turns, over ``kernel_rounds`` rounds: default 3, 1 with ``quick``), the
    cost per simulated second from 1e3 to 1e6 beads and the optional models' costs."""
    divisions = QUICK["divisions"] if quick else DIVISIONS
    settings = QUICK["settings"] if quick else SETTINGS
    names = QUICK["scenarios"] if quick else tuple(SCENARIOS)
    peer_settings = QUICK["peers"] if quick else PEERS
    rounds = 1 if quick else ROUNDS
    per_round: list[list] = [[] for _ in range(rounds)]
    notes: list = []
    for name, p, save, t_end in cases(names):
        if progress:
            progress(f"{name}: reference")
        ref = reference(p, t_end, save)
        runs = _ours(name, p, save, t_end, ref, divisions, settings)
        if peers:
            more, said = _peers(name, p, save, t_end, ref, peer_settings)
            runs += more
            notes += [n for n in said if n not in notes]
        for k, rows in enumerate(interleaved(runs, rounds, progress)):
            per_round[k] += rows
    notes += list(dict.fromkeys(f"LAMMPS: {r['note']}" for r in per_round[0] if r.get("note")))
    return dict(rows=median_rows(per_round), at_equal_error=equal_error_rounds(per_round), rounds=rounds,
                notes=notes, machine=machine(), beads=N_BEADS, probe_contact=PROBE,
                # three repeats even when quick: a lone first solve in a fresh process ran at twice the cost
                kernel=kernel_figures(3 if quick else 5, kernel_rounds or (1 if quick else 3), baseline, progress),
                scaling=None if quick else scaling(chain, progress), models=models.run(quick, progress))


def table(result: dict) -> str:
    head = f"{'scenario':14s} {'method':18s} {'setting':17s} {'CPU s':>8s} {'error':>9s} {'ns/bead/eval':>12s}"
    lines = [head, "-" * len(head)]
    for r in result["rows"]:
        ns = f"{r['ns_per_bead_eval']:12.2f}" if r["ns_per_bead_eval"] else f"{'-':>12s}"
        extra = f"  estimate {r['estimate']:.2e}, {r['attempts']} solves" if r.get("estimate") else ""
        lines.append(f"{r['scenario']:14s} {r['method']:18s} {r['setting']:17s} {r['cpu_s']:8.4f} "
                     f"{r['error']:9.2e} {ns}{extra}")
    lines += ["", f"At equal error: CPU seconds, interpolated log-log, and as a multiple of srkn6b's (fixed steps); "
                  f"medians over {result['rounds']} interleaved round(s)"]
    for r in result["at_equal_error"]:
        if r["cpu_s"] is not None:
            ratio = f"{r['ratio_to_srkn6b']:7.1f} x" if r["ratio_to_srkn6b"] else "      -"
            lines.append(f"  {r['scenario']:14s} {r['method']:18s} error {r['error']:.0e}  {r['cpu_s']:8.4f} s {ratio}")
    k = result["kernel"]
    lines += ["", f"Whole srkn6b step, ns per bead per force evaluation (CPU, medians of "
                  f"{k['rounds']} round(s)):"]
    for n in k["beads"]:
        base = (f"   baseline {k['baseline_rev']}: {k['baseline'][str(n)]:.2f}, ratio {k['ratio'][str(n)]:.2f}"
                if "baseline" in k else "")
        lines.append(f"  N = {n:>9,d}: {k['current'][str(n)]:.2f}{base}")
    b = k["bounds"]
    lines.append(f"  bounds: square root {b['sqrt_ns']:.2f} ns (vectorised); memory {b['bandwidth_GB_s']:.1f} GB/s, "
                 f"one pass per evaluation {b['memory_state_ns']:.2f} ns (state u, v, f) to "
                 f"{b['memory_all_ns']:.2f} ns (every array); the blocked sweep streams the arrays once per step")
    if result.get("scaling"):
        s = result["scaling"]
        lines += ["", f"CPU per simulated second at dt = {s['dt_s'] * 1e9:.0f} ns (the control's step for 1e3 beads):"]
        for r in s["rows"]:
            lines.append(f"  {r['beads']:>9,d} beads: {r['cpu_per_simulated_s']:10.2f} s/s")
        lines.append(f"  exponent of N: {s['exponent']:.3f}")
    lines += ["", models.table(result["models"])]
    lines += [f"note: {n}" for n in result["notes"]]
    return "\n".join(lines)
