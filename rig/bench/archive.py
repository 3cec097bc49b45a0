"""Archive benchmark (``rig bench archive``): virtual shots of 3 channels x 10,000 points
(ptfe52_magnetic with scope.record_length = 10000), appended in transactions of 100 shots
and, for comparison, one transaction per shot (what ``rig shot --out`` does). CPU time
(process time: the figures of one core, steadier than wall time on a shared machine; the
fsyncs' waits are not in them), medians of 3 runs into fresh files; then verify and
read-back rates; then, for an archive that already holds N shots, the median CPU time of a
one-shot append of such a shot and of reading one shot back (the first and the last): at 10
and 1,000 shots built by appends of 100 virtual shots (the same shots over again), at 10,000
and 100,000 shots written directly (rig/bench/archive_large.py: small real shots, parts of
1,000 shots made by HDF5's object copy, a master of links), which layouts 3 and 4 keep near
what the shot itself costs."""
from __future__ import annotations

import statistics
import tempfile
import time
from pathlib import Path

from instruments.archive import Archive
from rig.bench.archive_large import build
from rig.experiment.entry import shot_entry
from rig.experiment.shot import Rig


def run(shots: int = 400, batch: int = 100, single: int = 60, held: tuple = (10, 1000),
        large: tuple = (10_000, 100_000)) -> dict:
    rig = Rig.from_scene("ptfe52_magnetic", ["scope.record_length=10000"])
    entries = [shot_entry(rig.fire(seed=s)) for s in range(shots)]

    def rate(chunk, n):
        times = []
        for _ in range(3):
            with tempfile.TemporaryDirectory() as d:
                a = Archive(Path(d) / "bench.h5")
                t0 = time.process_time()
                for k in range(0, n, chunk):
                    a.append(entries[k:k + chunk])
                times.append(time.process_time() - t0)
        return n / statistics.median(times)

    batched = rate(batch, shots)
    one_by_one = rate(1, single)
    with tempfile.TemporaryDirectory() as d:
        a = Archive(Path(d) / "bench.h5")
        a.append(entries)
        files = [Path(d) / "bench.h5", *Path(d).glob("bench.h5.d/*.h5")]  # the master and its parts
        size = sum(p.stat().st_size for p in files)
        t0 = time.process_time()
        a.verify()
        verify = shots / (time.process_time() - t0)
        t0 = time.process_time()
        for i in a.ids():
            a.read(i, with_truth=False)
        read = shots / (time.process_time() - t0)
    return {"points_per_channel": 10000, "channels": 3, "shots": shots,
            "batched_shots_per_s": batched, "batch": batch,
            "single_shots_per_s": one_by_one, "verify_shots_per_s": verify,
            "read_shots_per_s": read, "bytes_per_shot": size / shots,
            "held": {**{n: _held(entries, n, batch) for n in held},
                     **{n: _held(entries, n, batch, True) for n in large}}}


def _held(entries: list, n: int, batch: int, direct: bool = False, repeats: int = 7) -> dict:
    """Medians (ms) of a one-shot append and of one shot read back, the first and the last,
    in an archive that holds ``n`` shots (``direct``: written directly, archive_large.build)."""
    with tempfile.TemporaryDirectory() as d:
        a = build(Path(d) / "bench.h5", n) if direct else Archive(Path(d) / "bench.h5")
        for k in range(0, 0 if direct else n, batch):
            a.append([entries[(k + i) % len(entries)] for i in range(min(batch, n - k))])
        append, read = [], []
        for r in range(repeats):
            t0 = time.process_time()
            (new,) = a.append([entries[r % len(entries)]])
            append.append(time.process_time() - t0)
            for i in (1, new):
                t0 = time.process_time()
                a.read(i, with_truth=False)
                read.append(time.process_time() - t0)
    return {"append_ms": 1e3 * statistics.median(append), "read_ms": 1e3 * statistics.median(read)}


def table(r: dict) -> str:
    return "\n".join([
        (f"archive: {r['shots']} virtual shots, {r['channels']} channels x {r['points_per_channel']} points, "
         "one core, CPU time"),
        f"  append, {r['batch']} shots per transaction   {r['batched_shots_per_s']:8.0f} shots/s",
        f"  append, one shot per transaction   {r['single_shots_per_s']:8.0f} shots/s",
        f"  verify (fletcher32 + sha256)       {r['verify_shots_per_s']:8.0f} shots/s",
        f"  read back (codes + metadata)       {r['read_shots_per_s']:8.0f} shots/s",
        f"  file size                          {r['bytes_per_shot'] / 1e3:8.1f} kB/shot",
        *(f"  holding {int(n):>7,} shots: one-shot append {h['append_ms']:6.1f} ms, "
          f"read one shot {h['read_ms']:5.1f} ms"
          for n, h in r.get("held", {}).items()),
        "  (10,000 and 100,000 shots: archives written directly, rig/bench/archive_large.py)"])
