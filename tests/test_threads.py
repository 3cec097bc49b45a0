"""numerics.threads: a compiled loop's ranges on numba's threads, the helper threads kept."""
import threading

import numba
import numpy as np
import pytest

from numerics.threads import over_threads


def _with_threads(n, call):
    was = numba.get_num_threads()
    numba.set_num_threads(min(n, numba.config.NUMBA_NUM_THREADS))
    try:
        return call()
    finally:
        numba.set_num_threads(was)


@pytest.mark.parametrize("n", [1, 2, 3, 17])
def test_every_item_is_in_exactly_one_range(n):
    seen = np.zeros(n, int)
    lock = threading.Lock()

    def run(lo, hi):
        with lock:
            seen[lo:hi] += 1

    _with_threads(2, lambda: over_threads(n, run))
    assert (seen == 1).all()


def test_the_helper_threads_are_started_once_and_the_caller_takes_a_range():
    if numba.config.NUMBA_NUM_THREADS < 2:
        pytest.skip("one core: every range runs in the caller")
    used = []

    def run(lo, hi):
        used.append(threading.current_thread())

    _with_threads(2, lambda: over_threads(10, run))
    alive = set(threading.enumerate())
    for _ in range(4):
        _with_threads(2, lambda: over_threads(10, run))
    assert used.count(threading.current_thread()) == 5  # the caller runs the first range of each call
    helpers = set(used) - {threading.current_thread()}
    assert helpers and helpers <= alive  # no thread started after the first call
    assert all(t.is_alive() for t in helpers)  # kept between calls


def test_an_error_in_a_range_comes_after_every_range_has_run():
    done = []

    def run(lo, hi):
        if lo == 0:
            raise ValueError("first range")
        threading.Event().wait(0.05)
        done.append(lo)

    with pytest.raises(ValueError, match="first range"):
        _with_threads(2, lambda: over_threads(4, run))
    if numba.config.NUMBA_NUM_THREADS >= 2:
        assert done == [2]  # the other range had finished when the error came


def test_callers_on_several_threads_share_the_helpers():
    totals = {}

    def caller(k):
        out = np.zeros(100)

        def run(lo, hi):
            out[lo:hi] = np.arange(lo, hi) * k

        _with_threads(2, lambda: over_threads(100, run))
        totals[k] = out.sum()

    threads = [threading.Thread(target=caller, args=(k,)) for k in range(1, 5)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert totals == {k: k * 4950.0 for k in range(1, 5)}


def test_the_time_in_ranges_is_counted_for_the_calling_thread():
    from numerics.threads import time_in_ranges

    before = time_in_ranges()
    _with_threads(2, lambda: over_threads(2, lambda lo, hi: threading.Event().wait(0.05)))
    spent = time_in_ranges() - before
    assert 0.05 <= spent < 1.0
    other = []
    t = threading.Thread(target=lambda: other.append(time_in_ranges()))
    t.start()
    t.join()
    assert other == [0.0]  # each thread its own clock
