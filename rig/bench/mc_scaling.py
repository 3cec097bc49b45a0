"""How ``rig mc`` scales with cores (the scaling table of ``rig bench mc``): the same study
at 1, 2, 4, ... up to the machine's cores, run four ways:

- ``workers``: ``rig mc --workers N``, N local worker processes on one numba thread each;
- ``dask``: a Dask LocalCluster of N single-threaded workers (``--scheduler local``), where
  Dask is installed;
- ``threads``: one process, the batch path on N numba threads;
- ``threads_batch``: the same at the batch ``rig mc`` takes in one process on N threads
  (rig.study.mc_spec.default_batch: 128 shots per thread, 256 at least, within the memory
  limit), in the table of rig mc's default batch only.

The rate of the first two is the steady one (shots stored after each worker's first
batch, over the time since: worker start-up and numba's cache loads left out); of the
last two the median batch after warm-up batches. Parallel efficiency is against 2 of the
same: rate_N / (N/2 x rate_2) (1 at N = 2), and against 1 for the single worker. Each
study runs ``PER_WORKER`` batches per worker, so that the last round's batches are a
small part of it.

Where the time goes, per batch: the parent's CPU in the steady part (handing batches out,
taking results in, storing them; on Dask the LocalCluster's scheduler runs in the parent
too), the workers' CPU (reaped children, so start-up included; none for one worker, which
runs in this process), and the bytes of one batch's result as it is pickled back; in one
process, a batch's time outside its compiled ranges over the shots (numerics/threads.py:
what runs on one thread whatever N is) and the efficiency that share allows at 4, 8 and 16
threads (Amdahl)."""
from __future__ import annotations

import dataclasses
import os
import pickle
import resource
import statistics
import tempfile
import time

from numerics.threads import time_in_ranges
from rig.study.batch import run_batch
from rig.study.distributions import parse_vary
from rig.study.executors import run_study
from rig.study.mc_run import held_per_shot
from rig.study.mc_spec import DEFAULT_BATCH, default_batch
from rig.study.montecarlo import MonteCarloStudy
from rig.study.store import Store

MODES = {"workers": "rig mc --workers N (processes, 1 numba thread each), steady",
         "dask": "Dask LocalCluster, N single-threaded workers, steady",
         "threads": "one process, N numba threads (batch path)",
         "threads_batch": "the same, rig mc's batch for N threads (128 per thread)"}
PER_WORKER = 8  # batches per worker in each study
THREAD_BATCHES = 4  # timed batches per thread count (after WARM_UP)
STORE_GROUP = 8  # batches stored at once in the store's timing
WARM_UP = 2


def counts(cores: int) -> list:
    """1, 2, 4, ... up to ``cores``, and ``cores`` itself."""
    out = [1]
    while out[-1] * 2 <= cores:
        out.append(out[-1] * 2)
    return out + ([cores] if out[-1] != cores else [])


def _study(vary: tuple, workers: int, batch: int, seed: int) -> MonteCarloStudy:
    return MonteCarloStudy("ptfe52_magnetic", tuple(parse_vary(vary)), PER_WORKER * workers * batch,
                           seed=seed, batch=batch)


def _children_cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def steady_run(study: MonteCarloStudy, workers: int, scheduler: str | None = None) -> dict:
    """Run ``study`` on ``workers`` (one worker: in this process, on one numba thread); its
    steady rate (shots/s), the parent's CPU per batch over the same steady part (ms), and
    the workers' CPU per batch (ms: reaped children, their start-up included)."""
    import numba

    ticks = []
    was = numba.get_num_threads()
    if workers == 1 and scheduler is None:
        numba.set_num_threads(1)  # rig mc --workers 1 on one core, as one worker of many runs
    try:
        with tempfile.TemporaryDirectory() as folder:
            store = Store(folder, study).open()
            children = _children_cpu()
            run_study(study, store, workers=workers, scheduler=scheduler,
                      progress=lambda n: ticks.append((time.perf_counter(), time.process_time(), n)))
            children = _children_cpu() - children
    finally:
        numba.set_num_threads(was)
    settled = ticks[workers - 1]  # each worker's first batch carries its start-up
    steady = ticks[workers:]
    return {"shots_per_s": sum(n for *_, n in steady) / (steady[-1][0] - settled[0]),
            "parent_cpu_ms_per_batch": (steady[-1][1] - settled[1]) / len(steady) * 1e3,
            "worker_cpu_ms_per_batch": children / study.n_batches * 1e3}


def thread_rate(study: MonteCarloStudy, threads: int) -> dict:
    """The batch path in this process on ``threads`` numba threads, medians over the timed
    batches: shots/s, a batch's wall time (ms) and its time outside the compiled ranges over
    the shots (ms: its Python, numpy and kernels called alone, which run on one thread
    whatever ``threads`` is)."""
    import numba

    was = numba.get_num_threads()
    numba.set_num_threads(threads)
    try:
        for b in range(WARM_UP):
            run_batch(study, b)
        wall, outside = [], []
        for b in range(WARM_UP, WARM_UP + THREAD_BATCHES):
            t0, r0 = time.perf_counter(), time_in_ranges()
            run_batch(study, b)
            wall.append(time.perf_counter() - t0)
            outside.append(wall[-1] - (time_in_ranges() - r0))
    finally:
        numba.set_num_threads(was)
    return {"shots_per_s": study.batch / statistics.median(wall),
            "outside_ranges_ms_per_batch": statistics.median(outside) * 1e3,
            "batch_ms": statistics.median(wall) * 1e3}


def amdahl_efficiency(serial: float, n: int, base: int = 2) -> float:
    """The most parallel efficiency vs ``base`` (rate_n / (n/base x rate_base)) one batch on n
    threads can have when a share ``serial`` of its time on one thread runs on one thread
    whatever n is: (serial + (1 - serial) / base) / (serial + (1 - serial) / n) / (n / base)."""
    return (serial + (1 - serial) / base) / (serial + (1 - serial) / n) / (n / base)


def run(vary: tuple, batch: int, ns: list | None = None) -> dict:
    """The scaling table's figures at the worker counts ``ns`` (default: 1, 2, 4, ... up to
    the machine's cores): {mode: {N: {"shots_per_s", "efficiency_vs_2", ...}}}, the counts,
    the batch size and one batch result's pickled bytes per shot."""
    import numba

    ns = sorted(ns or counts(os.cpu_count() or 1))
    try:
        import dask.distributed  # noqa: F401 - imported to find whether the dask extra is installed
        modes = ["workers", "dask", "threads"]
    except ImportError:
        modes = ["workers", "threads"]
    if batch == DEFAULT_BATCH:  # beside rig mc's default batch only
        modes.append("threads_batch")
    rows: dict[str, dict] = {m: {} for m in modes}
    held = held_per_shot(_study(vary, 1, batch, seed=3)).bytes if "threads_batch" in rows else 0.0

    def auto(n: int) -> int:  # rig mc's batch in one process on n threads
        return default_batch(n, held)

    for n in ns:
        rows["workers"][n] = steady_run(_study(vary, n, batch, seed=1), n)
        if "dask" in rows:
            rows["dask"][n] = steady_run(_study(vary, n, batch, seed=2), n, scheduler="local")
        # numba.config sets its options at import: a checker does not see them
        if n <= numba.config.NUMBA_NUM_THREADS:  # type: ignore[attr-defined]
            rows["threads"][n] = thread_rate(_study(vary, 1, batch, seed=3), n)
            if "threads_batch" in rows:
                rows["threads_batch"][n] = dict(thread_rate(_study(vary, 1, auto(n), seed=3), n), batch=auto(n))
    for by_n in rows.values():
        for n, row in by_n.items():
            row["efficiency_vs_2"] = _efficiency(by_n, n, 2)
            row["efficiency_vs_1"] = _efficiency(by_n, n, 1)
    study = _study(vary, 1, batch, seed=1)
    result = run_batch(study, 0)
    return {"counts": ns, "batch": batch, "modes": rows,
            "result_bytes_per_shot": len(pickle.dumps(result, pickle.HIGHEST_PROTOCOL)) / batch,
            "store_ms_per_batch": store_time(study, result)}


def store_time(study: MonteCarloStudy, result, group: int = STORE_GROUP, groups: int = 3) -> dict:
    """Wall time (ms) the store takes per batch, one batch at a time and in groups of
    ``group`` (as its writer stores batches that come while it is busy), in a temporary
    folder as the scaling studies' stores are: 1000 / ms is the batches/s one writer sustains."""
    out = {}
    with tempfile.TemporaryDirectory() as folder:
        store = Store(folder, study).open()
        for size in (1, group):
            t0 = time.perf_counter()
            for _ in range(groups):
                store.write_all([dataclasses.replace(result, batch=b) for b in range(size)])
            out[size] = (time.perf_counter() - t0) / (groups * size) * 1e3
    return out


def _efficiency(by_n: dict, n: int, base: int):
    """rate_n / (n/base x rate_base), or None where there is no rate at ``base``."""
    if base not in by_n or n < base:
        return None
    return by_n[n]["shots_per_s"] / (n / base * by_n[base]["shots_per_s"])


def table(r: dict) -> str:
    ns = r["counts"]
    lines = [(f"  scaling, batches of {r['batch']}, {PER_WORKER} per worker; shots/s (efficiency vs 2: "
              f"rate_N / (N/2 x rate_2); one run each)"),
             f"  {'':58s}" + "".join(f" {'N = ' + str(n):>14s}" for n in ns)]
    for mode, by_n in r["modes"].items():
        cells = []
        for n in ns:
            row = by_n.get(n)
            eff = row and (row["efficiency_vs_2"] if n >= 2 else None)
            cells.append(f" {'-':>14s}" if row is None else
                         f" {row['shots_per_s']:7.0f}" + (f" ({eff:4.0%})" if eff is not None else " " * 7))
        lines.append(f"  {MODES[mode]:58s}" + "".join(cells))
    auto = r["modes"].get("threads_batch", {})
    if auto:
        lines.append("  rig mc's batch in one process: "
                     + ", ".join(f"N = {n}: {row['batch']}" for n, row in auto.items()))
    for mode in ("workers", "dask"):
        by_n = r["modes"].get(mode, {})
        if by_n:
            lines.append(f"  per batch, {mode}: parent CPU ms (steady) / workers' CPU ms (start-up included): "
                         + ", ".join(f"N = {n}: {row['parent_cpu_ms_per_batch']:.1f} / "
                                     f"{row['worker_cpu_ms_per_batch']:.0f}" for n, row in by_n.items()))
    threads = r["modes"].get("threads", {})
    if 1 in threads:
        one = threads[1]
        serial = one["outside_ranges_ms_per_batch"] / one["batch_ms"]
        lines.append("  per batch, threads: outside the compiled ranges (one thread whatever N), ms: "
                     + ", ".join(f"N = {n}: {row['outside_ranges_ms_per_batch']:.1f} of {row['batch_ms']:.1f}"
                                 for n, row in threads.items())
                     + f"; {serial:.0%} on one thread bounds N threads' efficiency vs 2 (Amdahl) at "
                     + ", ".join(f"{amdahl_efficiency(serial, n):.0%} at N = {n}" for n in (4, 8, 16)))
    lines.append(f"  a batch's result as pickled back to the parent: {r['result_bytes_per_shot']:.0f} bytes per shot")
    if "store_ms_per_batch" in r:
        alone, grouped = (r["store_ms_per_batch"][k] for k in sorted(r["store_ms_per_batch"]))
        lines.append(f"  the store, per batch: {alone:.1f} ms one at a time, "
                     f"{grouped:.1f} ms in groups of {STORE_GROUP} "
                     f"(its writer keeps up with {1000 / grouped:.0f} batches/s, {1000 / grouped * r['batch']:.0f} "
                     f"shots/s)")
    return "\n".join(lines)
