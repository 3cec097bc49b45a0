"""Running a compiled loop over many items on numba's threads: ``kernel(lo, hi, *args)``, a
function compiled ``nogil``, called for contiguous pieces lo .. hi - 1 that cover the items
0 .. n - 1, on as many threads as numba's (numba.get_num_threads). A numba parallel loop does
the same at run time, but links and re-optimises the kernel it calls once more at compile time.

The calling thread takes the first piece; helper threads, started once per process and kept
(``Helpers``), join in. A batch of a study calls this five times (the shots' rest, solver,
pulse speeds, acquisition, analysis): a pool started and joined for each call cost 16 thread
starts per call on 16 cores, serial time of the order of the pieces' own. A piece that calls
``over_threads`` again runs its items in its own thread (the helpers may all be waiting on it).

Two costs that grow with the threads are kept off the pieces (measured on 16 cores, batches
of 256 shots):

- **Choosing the compiled kernel.** numba's dispatcher types every argument on each call,
  holding Python's lock: 40-330 us for these kernels (a solver's bundles of arrays), so 15
  helpers started one after another, the last 4.9 ms into an 8.6 ms solver pass. The caller
  now asks the dispatcher once (an empty piece) and every piece calls the compiled entry
  point it chose, which types nothing (``compiled``).
- **Uneven threads.** Pieces of equal size took from 2.8 to 4.9 ms on the threads of one
  pass (cores shared or slower, threads woken later). The items are cut into up to
  ``PIECES`` pieces per thread, and each thread takes the next piece not taken until none
  is left, so that a slow thread takes fewer.

Every item is in exactly one piece and the items are independent, so the bits are the same
however many threads run them and whichever takes which piece."""
from __future__ import annotations

import itertools
import os
import threading
import time
from collections.abc import Callable
from concurrent.futures import Future, ThreadPoolExecutor, wait

from numba import get_num_threads
from numba.core.dispatcher import Dispatcher

PIECES = 4  # pieces per thread: the threads end within about a piece (a quarter of a share) of each other
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

    def submit(self, task: Callable[[], None], count: int) -> list:
        """``task()`` on ``count`` helper threads: their Futures. The pool is grown (a new
        one; the old one's threads end after what was given them) and the tasks handed over
        under one lock, so that callers on several threads never hand tasks to a pool another
        has just replaced; their tasks queue in turn."""
        with self.lock:
            if self.pool is None or self.size < count:
                if self.pool is not None:
                    self.pool.shutdown(wait=False)
                self.pool = ThreadPoolExecutor(count, thread_name_prefix="numba-range", initializer=_mark_helper)
                self.size = count
            futures: list[Future] = []
            try:
                for _ in range(count):
                    futures.append(self.pool.submit(task))
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
    """Seconds the calling thread has spent in ``over_threads`` since it began (its pieces
    running, on every thread): a batch's time in its compiled loops over the shots. The
    rest of a batch's time (its Python, numpy, kernels called alone) runs on one thread
    however many numba has, which bounds what N threads can give (Amdahl)."""
    return getattr(LOCAL, "spent", 0.0)


def over_threads(n: int, kernel: Callable[..., None], *args) -> None:
    """Call ``kernel(lo, hi, *args)`` for contiguous pieces lo .. hi - 1 covering 0 .. n - 1,
    on as many threads as numba's (at most n): the first piece in this thread, the others
    taken in turn by this thread and the helpers; all in this thread where one suffices, or
    where this thread is a piece's already. ``kernel`` is a numba function compiled
    ``nogil`` (its arguments typed once, ``compiled``: ``kernel(0, 0, *args)`` must do
    nothing) or any callable. Returns when every piece has run; where a piece fails, the
    threads take no more pieces and the first error is raised once those running have
    ended. Every item is in exactly one piece, so a kernel whose items are independent gives
    the same bits however many threads run it."""
    if getattr(LOCAL, "inside", False):
        kernel(0, n, *args)
        return
    start = time.perf_counter()
    LOCAL.inside = True
    try:
        _run_pieces(n, kernel, args)
    finally:
        LOCAL.inside = False
        LOCAL.spent = time_in_ranges() + time.perf_counter() - start


def compiled(kernel: Callable[..., None], args: tuple) -> Callable[..., None]:
    """What to call for ``kernel(lo, hi, *args)`` on many threads: for a numba function with
    one compiled signature after it is dispatched on an empty piece (0, 0) with ``args``,
    that signature's entry point, which takes the arguments without typing them again (and
    lets Python's lock go as the function does); else ``kernel`` itself."""
    if not isinstance(kernel, Dispatcher):  # a plain callable
        return kernel
    kernel(0, 0, *args)  # numba picks, or compiles, the signature of these arguments' types
    signatures = kernel.signatures
    if len(signatures) != 1:  # which of several the dispatcher chose is not told
        return kernel
    return kernel.get_overload(signatures[0])


def _run_pieces(n: int, kernel: Callable[..., None], args: tuple) -> None:
    threads = max(1, min(n, get_num_threads()))
    if threads == 1:
        kernel(0, n, *args)
        return
    call = compiled(kernel, args)
    pieces = min(n, PIECES * threads)
    cuts = [n * k // pieces for k in range(pieces + 1)]
    taken = itertools.count()  # next() on it is atomic: each piece goes to one thread
    failed: list[BaseException] = []  # in the order they came: the first is raised

    def run_from(k: int) -> None:
        """Piece k, then the next not taken, until none is left or a piece failed."""
        while not failed and k < pieces:
            try:
                call(cuts[k], cuts[k + 1], *args)
            except BaseException as exc:  # noqa: BLE001 - raised in the caller once every thread has stopped
                failed.append(exc)
                return
            k = next(taken)

    first = next(taken)  # the caller's, taken before a helper (one started by this very call) could
    others = HELPERS.submit(lambda: run_from(next(taken)), threads - 1)
    try:
        run_from(first)
    finally:
        wait(others)  # the pieces write into the caller's arrays: none outlives this call
    for future in others:
        future.result()  # an error of the helpers' own (none expected: run_from keeps them)
    if failed:
        raise failed[0]
