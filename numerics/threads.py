"""Running a compiled loop over many items on numba's threads: the items 0 .. n - 1 cut into
contiguous ranges, one per thread (numba.get_num_threads), each range handed to a kernel
compiled ``nogil`` in one call. A numba parallel loop does the same at run time, but links
and re-optimises the kernel it calls once more at compile time."""
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor

from numba import get_num_threads


def over_threads(n: int, run_range: Callable[[int, int], None]) -> None:
    """Call ``run_range(lo, hi)`` for contiguous ranges covering 0 .. n - 1, one per thread
    (as many as numba's, at most n), each on a thread of its own; in this thread where one
    suffices. Every item is in exactly one range, so a kernel whose items are independent
    gives the same bits however many threads run it."""
    threads = max(1, min(n, get_num_threads()))
    cuts = [n * k // threads for k in range(threads + 1)]
    if threads == 1:
        run_range(0, n)
        return
    with ThreadPoolExecutor(threads) as pool:
        list(pool.map(run_range, cuts[:-1], cuts[1:]))
