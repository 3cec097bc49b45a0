"""Work-precision benchmark of the chain solver (``rig bench solver``).

Two 1000-bead steel chains struck by one bead mass at 0.44 m/s: sonic vacuum (no gravity,
no precompression) and precompressed (2.38 N from the top, wall at the bottom). Error:
max |F - F_ref| / max F_ref of the force history at contact 500 on a 10 MS/s grid, against
a converged reference (SRKN6b, dt = tau/400). Every project method is run at several
accuracy settings; scipy.integrate.solve_ivp DOP853 with a vectorised numpy right-hand side
is run at several rtol in the same process as the baseline. Wall times are medians.
"""
from __future__ import annotations

import platform
import statistics
import time

import numpy as np

from instruments.jit import jit
from rig.model.chain import Chain
from rig.model.parts import Bead, Striker, Wall
from rig.solver.kernels.forces import contact_forces
from rig.solver.problem import ChainProblem
from rig.solver.saveat import SaveAt
from rig.solver.solve import solve
from rig.solver.stepsize import DEFAULT_ACCURACY, contact_time_scale

N_BEADS = 1000
PROBE = 500
STEEL = dict(material="steel316", diameter="4.76 mm", mass="0.4501 g")
SCENARIOS = {  # name: (top force N, t_end s) -- t_end lets the pulse pass contact 500
    "sonic-vacuum": (0.0, 5.0e-3),
    "precompressed": (2.38, 4.6e-3),
}
SETTINGS = {"verlet": (1e-2, 1e-3, 1e-4), "srkn6b": (1e-2, 1e-3, 1e-4, 1e-5, 1e-6)}
DOP853_RTOL = (1e-6, 1e-8, 1e-10)
QUICK = dict(settings={"verlet": (1e-3,), "srkn6b": (1e-3, 1e-4)}, rtol=(1e-10,),
             scenarios=("sonic-vacuum",), repeats=1)


def chain(top_force: float) -> Chain:
    striker = Striker("steel316", "0.4501 g", "0.44 m/s")
    if top_force:
        return Chain([Bead(**STEEL)] * N_BEADS, striker=striker, wall=Wall(), gravity=0,
                     top_force=top_force)
    return Chain([Bead(**STEEL)] * N_BEADS, striker=striker, gravity=0)


def _error(f, ref):
    return float(np.max(np.abs(f - ref)) / np.max(ref))


def _median_solve(p, t_end, repeats, **kw):
    sols = [solve(p, t_end, **kw) for _ in range(repeats)]
    return sols[0], statistics.median(s.stats.wall_s for s in sols)


def dop853(p, save, t_end, rtol):
    """solve_ivp DOP853 on the same ChainProblem, numpy right-hand side."""
    from scipy.integrate import solve_ivp

    nb = p.n_bodies
    slot = save.channels(p.offset)[0][0, 0]
    sample_interval = save.sample_interval

    def forces(u):
        d = np.maximum(p.d0[1:] + u[:-1] - u[1:], 0.0)
        f = np.zeros(nb + 1)
        f[1:nb] = p.A[1:] * d * np.sqrt(d) - p.load[1:nb]
        f[nb] = -p.load[nb]
        return f

    def rhs(t, y):
        f = forces(y[:nb])
        return np.concatenate((y[nb:], (f[:-1] - f[1:]) * p.invm))

    t_eval = np.arange(int(t_end / sample_interval + 1e-9) + 1) * sample_interval
    y0 = np.concatenate((p.u0, p.v0))
    scale = np.concatenate((np.full(nb, 1e-5), np.full(nb, max(p.v0.max(), 1e-3))))
    t0 = time.perf_counter()
    r = solve_ivp(rhs, (0.0, t_end), y0, method="DOP853", t_eval=t_eval, rtol=rtol,
                  atol=rtol * scale)
    wall = time.perf_counter() - t0
    F = np.array([forces(r.y[:nb, j])[slot] + p.load[slot] for j in range(r.y.shape[1])])
    return F, wall, r.nfev


@jit
def _repeat_forces(u, v, A, d0, damping, load, f, reps):
    for _ in range(reps):
        contact_forces(u, v, A, d0, damping, 0, load, f)
        u[1] += 1e-30  # keep the loop from being hoisted


def force_kernel_ns_per_bead(p, reps: int = 20000) -> float:
    """Median cost (ns) of one Hertz force evaluation per bead, the kernel alone."""
    u = np.full(p.n_bodies, 1e-7) * np.arange(p.n_bodies) * -1.0  # all contacts closed
    v = np.zeros(p.n_bodies)
    f = np.zeros(p.n_bodies + 1)
    args = (u, v, p.A, p.d0, p.damping, p.load, f)
    _repeat_forces(*args, 1)
    times = []
    for _ in range(5):
        t0 = time.perf_counter()
        _repeat_forces(*args, reps)
        times.append((time.perf_counter() - t0) / reps / p.n_bodies * 1e9)
    return statistics.median(times)


def run(quick: bool = False, progress=None) -> dict:
    settings = QUICK["settings"] if quick else SETTINGS
    rtols = QUICK["rtol"] if quick else DOP853_RTOL
    names = QUICK["scenarios"] if quick else tuple(SCENARIOS)
    repeats = QUICK["repeats"] if quick else 3
    rows = []
    for name in names:
        top_force, t_end = SCENARIOS[name]
        c = chain(top_force)
        p = ChainProblem.from_chain(c)
        save = SaveAt({"c500": c.contact_probe(PROBE)})
        tau = contact_time_scale(p)
        ref = solve(p, t_end, save=save, dt=tau / 400).forces["c500"]
        for method, accs in settings.items():
            for acc in accs:
                if progress:
                    progress(f"{name}: {method} accuracy={acc:g}")
                sol, wall = _median_solve(p, t_end, repeats, save=save, method=method, accuracy=acc)
                rows.append(dict(
                    scenario=name, method=method, setting=f"accuracy={acc:g}", wall_s=wall,
                    error=_error(sol.forces["c500"], ref),
                    ns_per_bead_eval=wall / (sol.stats.force_evaluations * p.moving_bodies) * 1e9,
                    default=(method == "srkn6b" and acc == DEFAULT_ACCURACY),
                    dt_s=sol.stats.dt_s, energy_error=sol.stats.energy_error))
        for rtol in rtols:
            if progress:
                progress(f"{name}: scipy-DOP853 rtol={rtol:g}")
            F, wall, nfev = dop853(p, save, t_end, rtol)
            rows.append(dict(scenario=name, method="scipy-DOP853", setting=f"rtol={rtol:g}",
                             wall_s=wall, error=_error(F, ref),
                             ns_per_bead_eval=wall / (nfev * p.moving_bodies) * 1e9,
                             default=False, dt_s=None, energy_error=None))
        _speedups([r for r in rows if r["scenario"] == name])
    c = chain(2.38)
    return dict(rows=rows, machine=_machine(), beads=N_BEADS, probe_contact=PROBE,
                force_kernel_ns_per_bead=force_kernel_ns_per_bead(ChainProblem.from_chain(c)),
                matched_error=matched(rows))


TARGET_ERROR = 2e-4


def _speedups(rows, target=TARGET_ERROR):
    """speedup_vs_dop853: the cheapest DOP853 run with error <= target, over this row."""
    ok = [r["wall_s"] for r in rows if r["method"] == "scipy-DOP853" and r["error"] <= target]
    base = min(ok) if ok else None
    for r in rows:
        r["speedup_vs_dop853"] = base / r["wall_s"] if base else None


def matched(rows, target=TARGET_ERROR) -> list:
    """Per scenario and method: the cheapest run with error <= target, and its speed-up
    over DOP853's cheapest such run (the work-precision comparison at equal error)."""
    out = []
    for name in dict.fromkeys(r["scenario"] for r in rows):
        best = {}
        for r in rows:
            if r["scenario"] == name and r["error"] <= target:
                if r["method"] not in best or r["wall_s"] < best[r["method"]]["wall_s"]:
                    best[r["method"]] = r
        base = best.get("scipy-DOP853")
        for method, r in best.items():
            out.append(dict(scenario=name, method=method, setting=r["setting"], wall_s=r["wall_s"],
                            error=r["error"],
                            speedup_vs_dop853=base["wall_s"] / r["wall_s"] if base else None))
    return out


def _machine() -> str:
    model = platform.processor() or ""
    try:
        with open("/proc/cpuinfo") as fh:
            model = next((l.split(":", 1)[1].strip() for l in fh if l.startswith("model name")), model)
    except OSError:
        pass
    import os
    return f"{model} ({os.cpu_count()} cores), {platform.system()} {platform.machine()}"


def table(result: dict) -> str:
    head = f"{'scenario':14s} {'method':13s} {'setting':15s} {'wall_s':>9s} {'error':>9s} {'ns/bead/eval':>12s} {'x DOP853':>9s}"
    lines = [head, "-" * len(head)]
    for r in result["rows"]:
        sp = f"{r['speedup_vs_dop853']:.0f}" if r["speedup_vs_dop853"] else "-"
        mark = " *" if r["default"] else ""
        lines.append(f"{r['scenario']:14s} {r['method']:13s} {r['setting']:15s} {r['wall_s']:9.4f} "
                     f"{r['error']:9.2e} {r['ns_per_bead_eval']:12.2f} {sp:>9s}{mark}")
    lines.append("* default setting; x DOP853: wall time of the cheapest DOP853 run reaching "
                 "error <= 2e-4, divided by this row's")
    lines.append("")
    lines.append(f"At equal error (cheapest run with error <= {TARGET_ERROR:g}):")
    for r in result["matched_error"]:
        sp = f"{r['speedup_vs_dop853']:.0f}x DOP853" if r["speedup_vs_dop853"] else "no DOP853 run got there"
        lines.append(f"  {r['scenario']:14s} {r['method']:13s} {r['setting']:15s} {r['wall_s']:8.4f} s  "
                     f"error {r['error']:.2e}  {sp}")
    lines.append(f"Hertz force kernel alone: {result['force_kernel_ns_per_bead']:.3f} ns per bead per "
                 f"evaluation (N = {N_BEADS + 2}, one core)")
    return "\n".join(lines)
