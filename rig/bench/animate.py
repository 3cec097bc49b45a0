"""Animation benchmark (``rig bench animate``): 100 frames of ptfe52_magnetic rendered
off-screen to an mp4 (solve with frames, instruments, 3-D view, trace panel, encoding),
and the process's resident memory after frame 10 and after frame 100 (one plotter is
reused, so it should not grow). Median of 3 runs; the baseline is the same shot solved
without frames (what `rig shot` pays)."""
from __future__ import annotations

import os
import statistics
import tempfile
import time
from pathlib import Path

from rig.experiment.shot import Rig
from rig.viz.animate import animate

FRAMES = 100


def _rss_mib() -> float:
    """Resident memory of this process (MiB), from /proc (Linux)."""
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE") / 2**20


def run(repeats: int = 3) -> dict:
    times, grow = [], []
    with tempfile.TemporaryDirectory() as tmp:
        for k in range(repeats + 1):  # the first run loads the renderer and compiles
            rss: dict[int, float] = {}  # {frame: resident MiB}
            count = [0]

            def progress(count=count, rss=rss):  # bound: one counter per run
                count[0] += 1
                if count[0] in (10, FRAMES):
                    rss[count[0]] = _rss_mib()

            t0 = time.perf_counter()
            animate(Rig.from_scene("ptfe52_magnetic"), Path(tmp) / f"m{k}.mp4", frames=FRAMES, seed=1,
                    progress=progress)
            if k:
                times.append(time.perf_counter() - t0)
                grow.append(rss[FRAMES] - rss[10])
        size = (Path(tmp) / f"m{repeats}.mp4").stat().st_size
    t0 = time.perf_counter()
    Rig.from_scene("ptfe52_magnetic").fire(seed=1, truth=False)
    shot = time.perf_counter() - t0
    return {"frames": FRAMES, "median_s": statistics.median(times), "runs_s": times,
            "memory_growth_10_to_100_MiB": statistics.median(grow), "mp4_bytes": size, "shot_s": shot}


def table(r: dict) -> str:
    return "\n".join([
        f"animation of ptfe52_magnetic, {r['frames']} frames to mp4, off-screen (median of {len(r['runs_s'])})",
        f"  whole animation            {r['median_s']:7.2f} s   "
        f"({r['median_s'] / r['frames'] * 1e3:.0f} ms per frame; target < 20 s)",
        f"  the same shot, no frames   {r['shot_s']:7.2f} s",
        f"  memory, frame 10 -> 100    {r['memory_growth_10_to_100_MiB']:+7.1f} MiB",
        f"  movie size                 {r['mp4_bytes'] / 1e6:7.2f} MB"])
