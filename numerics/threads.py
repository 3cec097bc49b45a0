"""Running a compiled loop over many items on numba's threads: the items 0 .. n - 1 cut into
contiguous ranges, one per thread (numba.get_num_threads), each range handed to a kernel
compiled ``nogil`` in one call. A numba parallel loop does the same at run time, but links
and re-optimises the kernel it calls once more at compile time.

The calling thread takes the first range; helper threads, started once per process and
kept (``Helpers``), take the others. A batch calls this three times (solver, acquisition,
analysis): a pool started and joined for each call cost 16 thread starts per call on 16
cores, serial time of the order of the ranges' own."""
from __future__ import annotations

import os
import threading
import time
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor, wait

from numba import get_num_threads


class Helpers:
    """The process's helper threads: a thread pool grown to the most helpers asked so far,
    started anew in a forked child (whose copy of the pool has no threads)."""

    def __init__(self) -> None:
        self.lock = threading.Lock()
        self.pool: ThreadPoolExecutor | None = None
        self.size = 0
        self.pid = 0

    def at_least(self, count: int) -> ThreadPoolExecutor:
        """A pool of at least ``count`` threads; callers on several threads share it (their
        ranges queue, none waits on another's)."""
        with self.lock:
            if self.pool is None or self.size < count or self.pid != os.getpid():
                if self.pool is not None and self.pid == os.getpid():
                    self.pool.shutdown(wait=False)  # its queued ranges still run, then its threads end
                self.pool = ThreadPoolExecutor(count, thread_name_prefix="numba-range")
                self.size, self.pid = count, os.getpid()
            return self.pool


HELPERS = Helpers()
CLOCK = threading.local()  # .spent: seconds this thread has waited in over_threads


def time_in_ranges() -> float:
    """Seconds the calling thread has spent in ``over_threads`` since it began (its ranges
    running, on every thread): a batch's time in its compiled loops over the shots. The
    rest of a batch's time (its Python, numpy, kernels called alone) runs on one thread
    however many numba has, which bounds what N threads can give (Amdahl)."""
    return getattr(CLOCK, "spent", 0.0)


def over_threads(n: int, run_range: Callable[[int, int], None]) -> None:
    """Call ``run_range(lo, hi)`` for contiguous ranges covering 0 .. n - 1, one per thread
    (as many as numba's, at most n): the first in this thread, the others on helper threads;
    all in this thread where one suffices. Returns when every range has run; the first error
    of a range is raised then. Every item is in exactly one range, so a kernel whose items
    are independent gives the same bits however many threads run it."""
    start = time.perf_counter()
    try:
        _run_ranges(n, run_range)
    finally:
        CLOCK.spent = time_in_ranges() + time.perf_counter() - start


def _run_ranges(n: int, run_range: Callable[[int, int], None]) -> None:
    threads = max(1, min(n, get_num_threads()))
    cuts = [n * k // threads for k in range(threads + 1)]
    if threads == 1:
        run_range(0, n)
        return
    pool = HELPERS.at_least(threads - 1)
    others = [pool.submit(run_range, lo, hi) for lo, hi in zip(cuts[1:-1], cuts[2:])]
    try:
        run_range(cuts[0], cuts[1])
    finally:
        wait(others)  # the ranges write into the caller's arrays: none outlives this call
    for future in others:
        future.result()
