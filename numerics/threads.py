"""Running a compiled loop over many items on numba's threads: the items 0 .. n - 1 cut into
contiguous ranges, one per thread (numba.get_num_threads), each range handed to a kernel
compiled ``nogil`` in one call. A numba parallel loop does the same at run time, but links
and re-optimises the kernel it calls once more at compile time.

The calling thread takes the first range; helper threads, started once per process and
kept (``Helpers``), take the others. A batch of a study calls this four times (solver,
pulse speeds, acquisition, analysis): a pool started and joined for each call cost 16
thread starts per call on 16 cores, serial time of the order of the ranges' own. A range
that calls ``over_threads`` again runs its items in its own thread (the helpers may all be
waiting on it)."""
from __future__ import annotations

import os
import threading
import time
from collections.abc import Callable
from concurrent.futures import Future, ThreadPoolExecutor, wait

from numba import get_num_threads

LOCAL = threading.local()  # .spent: seconds this thread has spent in over_threads; .inside: in it now, or a helper


class Helpers:
    """The process's helper threads: a thread pool grown to the most helpers asked so far,
    started anew in a forked child (whose copy of the pool has no threads)."""

    lock: threading.Lock
    pool: ThreadPoolExecutor | None
    size: int

    def __init__(self) -> None:
        self.reset()

    def reset(self) -> None:
        """No pool yet (a forked child's state: the parent's threads are not in it)."""
        self.lock, self.pool, self.size = threading.Lock(), None, 0

    def submit(self, run_range: Callable[[int, int], None], ranges: list) -> list:
        """``run_range(lo, hi)`` of each (lo, hi) of ``ranges`` on a helper thread: their
        Futures. The pool is grown (a new one; the old one's threads end after what was given
        them) and the ranges handed over under one lock, so that callers on several threads
        never hand ranges to a pool another has just replaced; their ranges queue in turn."""
        with self.lock:
            if self.pool is None or self.size < len(ranges):
                if self.pool is not None:
                    self.pool.shutdown(wait=False)
                self.pool = ThreadPoolExecutor(len(ranges), thread_name_prefix="numba-range",
                                               initializer=_mark_helper)
                self.size = len(ranges)
            futures: list[Future] = []
            try:
                for lo, hi in ranges:
                    futures.append(self.pool.submit(run_range, lo, hi))
            except BaseException:
                wait(futures)  # none outlives the call that failed to hand over the rest
                raise
            return futures


def _mark_helper() -> None:
    LOCAL.inside = True


HELPERS = Helpers()
if hasattr(os, "register_at_fork"):  # POSIX: a forked child has none of the parent's threads
    os.register_at_fork(after_in_child=HELPERS.reset)


def time_in_ranges() -> float:
    """Seconds the calling thread has spent in ``over_threads`` since it began (its ranges
    running, on every thread): a batch's time in its compiled loops over the shots. The
    rest of a batch's time (its Python, numpy, kernels called alone) runs on one thread
    however many numba has, which bounds what N threads can give (Amdahl)."""
    return getattr(LOCAL, "spent", 0.0)


def over_threads(n: int, run_range: Callable[[int, int], None]) -> None:
    """Call ``run_range(lo, hi)`` for contiguous ranges covering 0 .. n - 1, one per thread
    (as many as numba's, at most n): the first in this thread, the others on helper threads;
    all in this thread where one suffices, or where this thread is a range's already.
    Returns when every range has run; the first error of a range is raised then. Every item
    is in exactly one range, so a kernel whose items are independent gives the same bits
    however many threads run it."""
    if getattr(LOCAL, "inside", False):
        run_range(0, n)
        return
    start = time.perf_counter()
    LOCAL.inside = True
    try:
        _run_ranges(n, run_range)
    finally:
        LOCAL.inside = False
        LOCAL.spent = time_in_ranges() + time.perf_counter() - start


def _run_ranges(n: int, run_range: Callable[[int, int], None]) -> None:
    threads = max(1, min(n, get_num_threads()))
    cuts = [n * k // threads for k in range(threads + 1)]
    if threads == 1:
        run_range(0, n)
        return
    others = HELPERS.submit(run_range, list(zip(cuts[1:-1], cuts[2:])))
    try:
        run_range(cuts[0], cuts[1])
    finally:
        wait(others)  # the ranges write into the caller's arrays: none outlives this call
    for future in others:
        future.result()
