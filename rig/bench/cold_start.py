"""Cold start-up benchmark (``rig bench startup --cold``): the first ``rig shot`` and the
first ``rig mc`` of a fresh install, where numba has compiled nothing yet, beside the same
commands once its cache is warm.

Each cold run is a fresh interpreter whose NUMBA_CACHE_DIR is an empty temporary folder
(every kernel it needs is compiled, as in a new venv or a CI run); each warm run reuses
the folder its cold run filled. A last row runs a shot in the folder the cold mc filled: a
study compiles the batched chain kernel only, so a shot after it compiles the single-shot
one (once). Times are wall seconds and the children's CPU seconds
(user + system: on several cores the compilation spread over processes makes CPU exceed
wall). The cold shot and the cold mc also report where their compilation went: each
kernel's compile time, exclusive of the kernels it calls (numba's ``numba:compile`` events,
wall seconds), the largest first, and how many functions numba compiled (numba's own
implementations included), in the command's own process; beside it the same in CPU seconds
of the compiling thread, and their part spent in LLVM (numba's ``numba:llvm_lock`` events:
optimising, emitting machine code), which a loaded machine does not inflate as it does the
wall seconds (two to three times at a load of 4 on 2 cores). ``--baseline REV`` measures
another revision in turns (one revision after the other in each round), so both see the
same machine load.
"""
from __future__ import annotations

import contextlib
import json
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

from rig.bench.startup import timed_child
from rig.errors import RigError

ROUNDS = 1  # a cold round costs tens of seconds
TARGETS = {"cold rig shot": 10.0, "cold rig mc": 20.0, "warm rig shot": 1.2}
SCENE = "ptfe52_magnetic"
STUDY = ["--vary", "striker.velocity=normal(0.89 m/s, 0.01 m/s)", "--shots", "64", "--batch", "64", "--quiet"]
# the rig's command line in a child that records each kernel's exclusive compile time into the file $RIG_COMPILE_LOG
# (wall and the compiling thread's CPU seconds; the LLVM seconds go to the kernel being compiled)
CHILD = """import json, os, sys, time
from numba.core import event
stack, count, got = [], [0], {"spent": {}, "cpu": {}, "llvm": {}}
def now():
    return time.perf_counter(), time.thread_time()
class Compiles(event.Listener):
    def on_start(self, ev):
        f = ev.data["dispatcher"].py_func
        stack.append([f"{f.__module__}.{f.__qualname__}", now(), [0.0, 0.0]])
        count[0] += 1
    def on_end(self, ev):
        name, t0, inner = stack.pop()
        dt = [b - a for a, b in zip(t0, now())]
        for key, d, i in zip(("spent", "cpu"), dt, inner):
            got[key][name] = got[key].get(name, 0.0) + d - i
        if stack:
            stack[-1][2] = [i + d for i, d in zip(stack[-1][2], dt)]
class Llvm(event.Listener):  # LLVM's lock is reentrant: the outermost hold counts
    depth = 0
    def on_start(self, ev):
        self.depth += 1
        if self.depth == 1:
            self.t0 = time.thread_time()
    def on_end(self, ev):
        self.depth -= 1
        if self.depth == 0:
            name = stack[-1][0] if stack else "-"
            got["llvm"][name] = got["llvm"].get(name, 0.0) + time.thread_time() - self.t0
event.register("numba:compile", Compiles())
event.register("numba:llvm_lock", Llvm())
from rig.cli import main
try:
    code = main(sys.argv[1:])
finally:
    with open(os.environ["RIG_COMPILE_LOG"], "w") as fh:
        json.dump({**got, "count": count[0]}, fh)
sys.exit(code)
"""


def _run(tree: Path | None, argv: list, cache: Path, log: Path) -> tuple:
    """(wall s, CPU s, {"spent": {kernel: exclusive compile s}, "cpu": {kernel: its CPU s}, "llvm": {kernel: the
    LLVM part of its CPU s}, "count": functions compiled}) of one rig command with numba's cache in ``cache``."""
    path = [str(tree)] if tree else []
    env = dict(os.environ, NUMBA_CACHE_DIR=str(cache), RIG_COMPILE_LOG=str(log),
               PYTHONPATH=os.pathsep.join(path + [os.environ.get("PYTHONPATH", "")]))
    try:
        wall, cpu, _ = timed_child([sys.executable, "-c", CHILD, *argv], cwd=str(tree or Path.cwd()), env=env)
    except subprocess.CalledProcessError as exc:
        raise RigError(f"rig bench startup --cold: `rig {' '.join(argv)}` failed (exit {exc.returncode})") from None
    return wall, cpu, json.loads(log.read_text())


def measure_revision(tree: Path | None, folder: Path) -> dict:
    """One round of one revision (``tree``: its checkout; None: this code): cold shot, cold
    mc, then the warm shot and mc, then a shot after the cold mc. Seconds, and the cold
    commands' compile times by kernel."""
    shot = ["shot", SCENE, "--seed", "1"]
    cold_shot, cold_mc, log = folder / "cache-shot", folder / "cache-mc", folder / "compiles.json"
    rows = {}
    rows["cold rig shot"] = _run(tree, shot, cold_shot, log)
    rows["cold rig mc"] = _run(tree, ["mc", SCENE, *STUDY, "--out", str(folder / "mc-cold")], cold_mc, log)
    rows["warm rig shot"] = _run(tree, shot, cold_shot, log)
    rows["warm rig mc"] = _run(tree, ["mc", SCENE, *STUDY, "--out", str(folder / "mc-warm")], cold_mc, log)
    rows["rig shot after a cold mc"] = _run(tree, shot, cold_mc, log)
    return {"wall_s": {k: v[0] for k, v in rows.items()}, "cpu_s": {k: v[1] for k, v in rows.items()},
            **{f"{task}_compiles{part}_s": rows[f"cold rig {task}"][2][key] for task in ("shot", "mc")
               for part, key in (("", "spent"), ("_cpu", "cpu"), ("_llvm_cpu", "llvm"))},
            "compiled": {k: v[2]["count"] for k, v in rows.items() if k.startswith("cold")}}


def run(rounds: int = ROUNDS, baseline: str | None = None) -> dict:
    from rig.bench.baseline import checkout

    revisions = {"current": None}
    with contextlib.ExitStack() as stack:
        if baseline:
            revisions[f"baseline {baseline}"] = stack.enter_context(checkout(baseline))
        got: dict[str, list] = {name: [] for name in revisions}
        for _ in range(rounds):
            for name, tree in revisions.items():
                with tempfile.TemporaryDirectory() as tmp:
                    got[name].append(measure_revision(tree, Path(tmp)))
    result: dict = {"rounds": rounds, "cores": os.cpu_count(), "scene": SCENE, "study": " ".join(STUDY),
              "targets_s": TARGETS, "revisions": {}}
    for name, runs in got.items():
        commands = runs[0]["wall_s"]
        rev = result["revisions"][name] = {
            "wall_s": {c: statistics.median(r["wall_s"][c] for r in runs) for c in commands},
            "cpu_s": {c: statistics.median(r["cpu_s"][c] for r in runs) for c in commands},
            "functions_compiled": {c: statistics.median(r["compiled"][c] for r in runs) for c in runs[0]["compiled"]}}
        for task in ("shot", "mc"):
            for part in ("", "_cpu", "_llvm_cpu"):
                compiles = {k: statistics.median(r[f"{task}_compiles{part}_s"].get(k, 0.0) for r in runs)
                            for k in runs[0][f"{task}_compiles{part}_s"]}
                rev[f"{task}_compile{part}_total_s"] = sum(compiles.values())
                rev[f"{task}_top_compiles{part}_s"] = (dict(sorted(compiles.items(), key=lambda kv: -kv[1])[:12])
                                                       if part == "" else compiles)
    if baseline:
        cur = result["revisions"]["current"]
        pairs = list(zip(got["current"], got[f"baseline {baseline}"]))
        result["ratio_to_baseline"] = {c: statistics.median(a["wall_s"][c] / b["wall_s"][c] for a, b in pairs)
                                       for c in cur["wall_s"]}
    return result


def table(r: dict) -> str:
    names = list(r["revisions"])
    lines = [f"cold start: an empty numba cache in a fresh interpreter ({SCENE}; mc: {r['study']}); "
             f"medians of {r['rounds']} round(s), {r['cores']} cores",
             f"  {'command':24s}" + "".join(f" {n[:22]:>22s}" for n in names)
             + (f" {'ratio':>6s}" if "ratio_to_baseline" in r else "") + f" {'target s':>8s}"]
    for command in r["revisions"]["current"]["wall_s"]:
        cells = "".join(f" {r['revisions'][n]['wall_s'][command]:9.2f} s "
                        f"({r['revisions'][n]['cpu_s'][command]:5.1f} CPU)" for n in names)
        ratio = f" {r['ratio_to_baseline'][command]:6.2f}" if "ratio_to_baseline" in r else ""
        target = TARGETS.get(command)
        lines.append(f"  {command:24s}{cells}{ratio} {'-' if target is None else f'{target:.1f}':>8s}")
    for n, task in ((n, task) for n in names for task in ("shot", "mc")):
        rev = r["revisions"][n]
        total, cpu, llvm = (rev[f"{task}_compile{part}_total_s"] for part in ("", "_cpu", "_llvm_cpu"))
        lines.append(f"  {n}: the cold {task}'s compile time by kernel (exclusive wall s; {total:.1f} s "
                     f"in all, {rev['functions_compiled'][f'cold rig {task}']:.0f} functions compiled, in its own "
                     f"process; CPU s: {cpu:.1f} in all, LLVM {llvm:.1f}):")
        lines += [f"    {k:60s} {v:6.2f}  CPU {rev[f'{task}_top_compiles_cpu_s'].get(k, 0.0):5.2f}  LLVM "
                  f"{rev[f'{task}_top_compiles_llvm_cpu_s'].get(k, 0.0):5.2f}"
                  for k, v in rev[f"{task}_top_compiles_s"].items()]
    return "\n".join(lines)
