"""A baseline measured in the same run: another revision of the rig, checked out into a
temporary git worktree, runs the same measurement in a subprocess, in turns with the
current code (``--baseline REV`` of ``rig bench solver`` and ``rig bench mc``).

The machine is shared and its speed drifts by a factor 2 or more over a day, so a figure
means something only beside one taken in the same minutes: each round runs the current
code and the baseline one after the other, and the benchmark reports medians and the
median of the per-round ratios. A measurement is a Python snippet that prints one JSON
object; it must use only what both revisions have (the public API of the solver and the
study)."""
from __future__ import annotations

import contextlib
import json
import os
import platform
import subprocess
import sys
import tempfile
from pathlib import Path

from rig.errors import RigError

ROOT = Path(__file__).resolve().parents[2]


def machine(cpuinfo: str = "/proc/cpuinfo") -> str:
    """The CPU a benchmark's figures come from: its model, its widest vector extension
    (AVX-512, AVX2 or neither, from the flags in ``cpuinfo``: the kernels' floor, the square
    roots' throughput, depends on it) and the cores Python sees."""
    model, flags = "", set[str]()
    try:
        with open(cpuinfo) as fh:
            for line in fh:
                key, _, value = line.partition(":")
                if key.strip() == "model name" and not model:
                    model = value.strip()
                elif key.strip() == "flags" and not flags:
                    flags = set(value.split())
    except OSError:
        pass
    model = model or platform.processor() or "unknown CPU"
    vector = "AVX-512" if "avx512f" in flags else "AVX2" if "avx2" in flags else "no AVX2"
    return f"{model}, {vector} ({os.cpu_count()} cores), {platform.system()} {platform.machine()}"


def check_revision(rev: str) -> None:
    """Refuse, before anything is measured, a revision this checkout cannot check out."""
    if not (ROOT / ".git").exists():
        raise RigError(f"--baseline {rev}: the rig is not run from a git checkout, so no other revision is at hand")
    done = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--verify", "--quiet", f"{rev}^{{commit}}"],
                          capture_output=True, text=True)
    if done.returncode:
        raise RigError(f"--baseline {rev}: no such revision in this checkout (a commit, a tag or a branch: "
                       f"git log --oneline lists them)")


@contextlib.contextmanager
def checkout(rev: str):
    """A temporary worktree of revision ``rev`` of this checkout (its path), removed after."""
    check_revision(rev)
    folder = Path(tempfile.mkdtemp(prefix="rig-baseline-")) / "tree"
    done = subprocess.run(["git", "-C", str(ROOT), "worktree", "add", "--detach", str(folder), rev],
                          capture_output=True, text=True)
    if done.returncode:
        raise RigError(f"--baseline {rev}: git cannot check it out ({done.stderr.strip().splitlines()[-1]})")
    try:
        yield folder
    finally:
        subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force", str(folder)], capture_output=True)


def measure(tree: Path, snippet: str, timeout: float = 900.0) -> dict:
    """Run ``snippet`` with the rig of ``tree`` first on the path; its JSON output."""
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(tree), os.environ.get("PYTHONPATH", "")]))
    done = subprocess.run([sys.executable, "-c", snippet], cwd=tree, env=env, capture_output=True, text=True,
                          timeout=timeout)
    if done.returncode:
        last = (done.stderr.strip().splitlines() or ["no message"])[-1]
        raise RigError(f"the measurement failed in {tree.name}: {last}")
    return json.loads(done.stdout.strip().splitlines()[-1])
