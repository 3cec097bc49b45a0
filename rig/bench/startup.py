"""Start-up benchmark (``rig bench startup``): how long the command line takes from a cold
interpreter with warm numba caches, against baselines measured in the same run.

Fresh subprocesses, interleaved (one of each per round), medians of wall and CPU time
(the children's user + system time). Baselines: ``python -c pass`` (the interpreter), and
the floor of any numba program here: importing numba and calling one tiny cached kernel.
The top imports (cumulative, ``python -X importtime``) of ``rig --help`` and of the shot
show where the rest goes.
"""
from __future__ import annotations

import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROUNDS = 7
TARGETS = {"rig --help": 0.15, "rig shot ptfe52_magnetic --seed 1": 0.8}
NUMBA_FLOOR = """import numpy as np
from numba import njit


@njit(cache=True)
def total(x):
    s = 0.0
    for i in range(x.shape[0]):
        s += x[i]
    return s


total(np.ones(3))
"""
RIG = "import sys; from rig.cli import main; sys.exit(main(sys.argv[1:]))"


def _commands(folder: Path) -> dict:
    floor = folder / "numba_floor.py"
    floor.write_text(NUMBA_FLOOR)
    return {"python -c pass": [sys.executable, "-c", "pass"],
            "numba import + one cached kernel": [sys.executable, str(floor)],
            "rig --help": [sys.executable, "-c", RIG, "--help"],
            "rig shot ptfe52_magnetic --seed 1": [sys.executable, "-c", RIG, "shot", "ptfe52_magnetic", "--seed", "1"]}


def timed_child(cmd: list, cwd: str | None = None, check: bool = True, env: dict | None = None) -> tuple:
    """(wall s, CPU s (the child's user + system), its stdout) of one run of ``cmd`` (in
    environment ``env``; None: this process's)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    done = subprocess.run(cmd, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True, check=check,
                          env=env)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime), done.stdout


def _top_imports(cmd: list, cwd: str, n: int = 10) -> list:
    """The n imports with the largest cumulative time (s) under python -X importtime."""
    out = subprocess.run([cmd[0], "-X", "importtime", *cmd[1:]], cwd=cwd, capture_output=True, text=True,
                         check=True)
    rows = []
    for line in out.stderr.splitlines():
        parts = line.split("|")
        if len(parts) == 3 and parts[1].strip().isdigit():
            rows.append((int(parts[1]) * 1e-6, parts[2].rstrip()))
    return [{"module": name.strip(), "depth": (len(name) - len(name.lstrip())) // 2, "cumulative_s": t}
            for t, name in sorted(rows, reverse=True)[:n]]


def run(rounds: int = ROUNDS) -> dict:
    with tempfile.TemporaryDirectory() as tmp:
        cmds = _commands(Path(tmp))
        for cmd in cmds.values():  # warm the caches (numba, the file system)
            timed_child(cmd, tmp)
        wall: dict[str, list] = {name: [] for name in cmds}
        cpu: dict[str, list] = {name: [] for name in cmds}
        for _ in range(rounds):
            for name, cmd in cmds.items():
                w, c, _ = timed_child(cmd, tmp)
                wall[name].append(w)
                cpu[name].append(c)
        imports = {name: _top_imports(cmds[name], tmp) for name in TARGETS}
    base = statistics.median(wall["python -c pass"])
    rows = [{"command": name, "wall_s": statistics.median(wall[name]), "cpu_s": statistics.median(cpu[name]),
             "ratio_to_python": statistics.median(wall[name]) / base, "target_s": TARGETS.get(name),
             "meets_target": None if name not in TARGETS else statistics.median(wall[name]) < TARGETS[name]}
            for name in cmds]
    floor = statistics.median(wall["numba import + one cached kernel"])
    shot = statistics.median(wall["rig shot ptfe52_magnetic --seed 1"])
    return {"rounds": rounds, "python": sys.version.split()[0], "cores": os.cpu_count(), "rows": rows,
            "shot_above_numba_floor_s": shot - floor, "top_imports": imports}


def table(r: dict) -> str:
    lines = [f"start-up from a fresh interpreter, warm caches (medians of {r['rounds']} interleaved rounds)",
             f"  {'command':36s} {'wall s':>7s} {'CPU s':>7s} {'x python':>8s} {'target s':>8s}"]
    for row in r["rows"]:
        target = "-" if row["target_s"] is None else f"{row['target_s']:.2f}"
        lines.append(f"  {row['command']:36s} {row['wall_s']:7.3f} {row['cpu_s']:7.3f} "
                     f"{row['ratio_to_python']:8.1f} {target:>8s}")
    if "shot_above_numba_floor_s" in r:
        lines.append(f"  the shot above the numba floor: {r['shot_above_numba_floor_s']:.3f} s")
    for name, top in r["top_imports"].items():
        lines.append(f"  top imports of `{name}` (cumulative s):")
        lines += [f"    {'  ' * row['depth']}{row['module']:40s} {row['cumulative_s']:.3f}" for row in top[:6]]
    return "\n".join(lines)
