"""What the srkn6b step costs (``rig bench solver``): ns per bead per force evaluation at
1e3 and 1e6 beads beside the machine's bounds, with a baseline revision measured in turns,
and the cost per simulated second from 1e3 to 1e6 beads."""
from __future__ import annotations

import contextlib
import dataclasses
import inspect
import statistics
import time

import numpy as np

from rig.bench.kernels.bounds import sqrt_ns, triad_bandwidth
from rig.solver.problem import ChainProblem
from rig.solver.saveat import SaveAt
from rig.solver.solve import solve
from rig.solver.stepsize import stepping_at

KERNEL_SIZES = ((1000, 4000, 5), (1_000_000, 300, 1))  # (beads, steps, repeats) of the kernel figure
SCALING_SIZES = (1000, 10_000, 100_000, 1_000_000)
SCALING_PROBE, SCALING_T = 50, 1e-3  # the pulse passes contact 50 in about 0.4 ms
SAMPLE_INTERVAL = 1e-6  # s: the probe's output grid, the same for every solver of the benchmark (1 MS/s)

def median_cpu(fn, repeats: int):
    """(result of the first call, median CPU seconds over ``repeats`` calls)."""
    times, first = [], None
    for _ in range(repeats):
        t0 = time.process_time()
        out = fn()
        times.append(time.process_time() - t0)
        first = out if first is None else first
    return first, statistics.median(times)



def in_motion(p):
    """Problem ``p`` with every bead moving at the start (the striker as it is; each bead
    1e-4 m/s up or down, seeded): the kernel figures time every body of every step, where a
    struck chain at rest would have the solver integrate only the bodies the pulse has
    reached (rig/solver/kernels/integrators.py)."""
    v0 = p.v0.copy()
    beads = slice(p.offset, p.offset + p.chain.n_beads)
    v0[beads] = 1e-4 * np.random.default_rng(7).choice((-1.0, 1.0), size=p.chain.n_beads)
    return dataclasses.replace(p, v0=v0)


# The kernel figure, as a program both this revision and a baseline run: public API only
# (and in_motion's source, prepended).
KERNEL_SNIPPET = """
import inspect, json, statistics, time
from rig import Bead, Chain, ChainProblem, SaveAt, Striker, Wall, solve
from rig.solver.stepsize import contact_time_scale
quiet = {"estimate": False} if "estimate" in inspect.signature(solve).parameters else {}
out = {}
for n, steps, repeats in SIZES:
    bead = Bead(material="steel316", diameter="4.76 mm", mass="0.4501 g")
    c = Chain([bead] * n, striker=Striker("steel316", "0.4501 g", "0.44 m/s"), wall=Wall(), gravity=0,
              top_force=2.38)
    p = in_motion(ChainProblem.from_chain(c))
    save = SaveAt({"c": c.contact_probe(min(500, n // 2))}, sample_interval=1e-6)
    dt = contact_time_scale(p) / 8
    solve(p, 2 * dt, save=save, dt=dt, **quiet)
    ns = []
    for _ in range(repeats):
        t0 = time.process_time()
        s = solve(p, steps * dt, save=save, dt=dt, **quiet)
        ns.append((time.process_time() - t0) / (s.stats.force_evaluations * (p.n_bodies - 1)) * 1e9)
    out[str(n)] = statistics.median(ns)
print(json.dumps(out))
"""



def kernel_figures(repeats: int, rounds: int, baseline: str | None, progress=None) -> dict:
    """ns per bead per force evaluation of the whole srkn6b step (KERNEL_SNIPPET), this
    revision and, with ``baseline``, that revision in turns; medians over the rounds."""
    from rig.bench.baseline import ROOT, checkout, measure

    sizes = tuple((n, steps, min(r, repeats)) for n, steps, r in KERNEL_SIZES)
    snippet = f"import dataclasses\nimport numpy as np\nSIZES = {sizes!r}\n" + inspect.getsource(in_motion) + \
        KERNEL_SNIPPET
    runs: dict[str, list] = {"current": [], "baseline": []}
    with checkout(baseline) if baseline else contextlib.nullcontext() as tree:
        for k in range(rounds):
            if progress:
                progress(f"kernel figure, round {k + 1} of {rounds}")
            runs["current"].append(measure(ROOT, snippet))
            if tree is not None:
                runs["baseline"].append(measure(tree, snippet))
    out: dict = {"beads": [n for n, *_ in KERNEL_SIZES], "baseline_rev": baseline, "rounds": rounds}
    for who, rs in runs.items():
        if rs:
            out[who] = {str(n): statistics.median(r[str(n)] for r in rs) for n, *_ in KERNEL_SIZES}
    if runs["baseline"]:
        pairs = list(zip(runs["current"], runs["baseline"]))
        out["ratio"] = {str(n): statistics.median(c[str(n)] / b[str(n)] for c, b in pairs) for n, *_ in KERNEL_SIZES}
    gbs = triad_bandwidth()
    out["bounds"] = {"sqrt_ns": sqrt_ns(), "bandwidth_GB_s": gbs,
                     # one pass over the state per evaluation: u, v, f read and written (48 B);
                     # every array (u, v, f read and written, invm, A, d0, load read: 80 B)
                     "memory_state_ns": 48.0 / gbs, "memory_all_ns": 80.0 / gbs}
    return out


def scaling(chain, progress=None) -> dict:
    """CPU per simulated second from 1e3 to 1e6 beads (``chain(top_force, n)``: the
    precompressed benchmark chain, the force of
    contact SCALING_PROBE, which the pulse passes within SCALING_T), at the step the accuracy
    control picks for 1e3 beads at the default accuracy, and the exponent of N. Every bead
    is set moving (in_motion), so that this is the cost of the whole chain: a struck chain
    at rest costs only the bodies the pulse has reached."""
    p0 = ChainProblem.from_chain(chain(2.38))
    save0 = SaveAt({"c": chain(2.38).contact_probe(SCALING_PROBE)}, SAMPLE_INTERVAL)
    t_end = SCALING_T
    stepping = stepping_at(p0, solve(p0, t_end, save=save0).stats.dt_s)
    rows = []
    for n in SCALING_SIZES:
        if progress:
            progress(f"scaling: {n} beads")
        c = chain(2.38, n)
        p = in_motion(ChainProblem.from_chain(c))
        save = SaveAt({"c": c.contact_probe(SCALING_PROBE)}, SAMPLE_INTERVAL)
        steps = max(100, int(2e7 / n))
        span = steps * stepping.dt
        solve(p, 2 * stepping.dt, save=save, dt=stepping, estimate=False)
        _, cpu = median_cpu(lambda p=p, span=span, save=save: solve(p, span, save=save, dt=stepping, estimate=False), 3)
        rows.append({"beads": n, "cpu_per_simulated_s": cpu / span, "steps": steps})
    log_n = np.log([r["beads"] for r in rows])
    log_c = np.log([r["cpu_per_simulated_s"] for r in rows])
    return {"dt_s": stepping.dt, "rows": rows, "exponent": float(np.polyfit(log_n, log_c, 1)[0])}
