"""numerics.threads: a compiled loop's ranges on numba's threads, the helper threads kept."""
import os
import threading

import numba
import numpy as np
import pytest

from numerics.threads import HELPERS, PIECES, compiled, over_threads, time_in_ranges

MANY = numba.config.NUMBA_NUM_THREADS >= 2
needs_two = pytest.mark.skipif(not MANY, reason="one core: every range runs in the caller")


def _with_threads(n, call):
    was = numba.get_num_threads()
    numba.set_num_threads(min(n, numba.config.NUMBA_NUM_THREADS))
    try:
        return call()
    finally:
        numba.set_num_threads(was)


def _in_time(target, seconds=20.0):
    """Run ``target`` on a thread; False where it has not ended after ``seconds`` (a hang)."""
    t = threading.Thread(target=target, daemon=True)
    t.start()
    t.join(seconds)
    return not t.is_alive()


@pytest.mark.parametrize("n", [1, 2, 3, 17])
def test_every_item_is_in_exactly_one_range(n):
    seen = np.zeros(n, int)
    lock = threading.Lock()

    def run(lo, hi):
        with lock:
            seen[lo:hi] += 1

    _with_threads(2, lambda: over_threads(n, run))
    assert (seen == 1).all()


@needs_two
def test_the_helper_threads_are_kept_and_the_caller_takes_the_first_piece():
    firsts, used = [], []

    def run(lo, hi):
        used.append(threading.current_thread())
        if lo == 0:
            firsts.append(threading.current_thread())
        threading.Event().wait(0.002)  # long enough for a helper to wake and take pieces too

    HELPERS.reset()  # a pool started by the first call: its new thread must not take the caller's piece
    _with_threads(2, lambda: over_threads(10, run))
    pool = HELPERS.pool
    for _ in range(4):
        _with_threads(2, lambda: over_threads(10, run))
    assert HELPERS.pool is pool  # the same pool for every call: no thread started and joined per call
    assert firsts == [threading.current_thread()] * 5  # the caller runs the first piece of each call
    helpers = set(used) - {threading.current_thread()}
    assert helpers and all(t.name.startswith("numba-range") and t.is_alive() for t in helpers)


def test_the_items_are_cut_into_pieces_that_the_threads_take_in_turn():
    # up to PIECES pieces per thread, contiguous, in order of lo, each taken once
    pieces = []
    lock = threading.Lock()

    def run(lo, hi):
        with lock:
            pieces.append((lo, hi))

    _with_threads(2, lambda: over_threads(100, run))
    threads = min(2, numba.config.NUMBA_NUM_THREADS)
    pieces.sort()
    assert len(pieces) == (PIECES * threads if threads > 1 else 1)
    assert [lo for lo, _ in pieces[1:]] == [hi for _, hi in pieces[:-1]] and pieces[0][0] == 0 and pieces[-1][1] == 100


@needs_two
def test_a_slow_thread_takes_fewer_pieces():
    # the caller's first piece is slow: the helper takes every other piece meanwhile
    by = {}
    lock = threading.Lock()

    def run(lo, hi):
        if lo == 0:
            threading.Event().wait(0.3)
        with lock:
            by.setdefault(threading.current_thread().name, []).append(lo)

    HELPERS.reset()
    _with_threads(2, lambda: over_threads(8, run))
    assert by[threading.current_thread().name] == [0]
    assert sorted(sum(by.values(), [])) == list(range(8))


def test_an_error_in_a_piece_comes_after_every_piece_begun_has_run_and_stops_the_rest():
    begun, done = [], []

    def run(lo, hi):
        begun.append(lo)
        if lo == 0:
            threading.Event().wait(0.05)
            raise ValueError("first piece")
        threading.Event().wait(0.04)
        done.append(lo)

    with pytest.raises(ValueError, match="first piece"):
        _with_threads(2, lambda: over_threads(100, run))  # 8 pieces on 2 threads
    assert sorted(done) == sorted(lo for lo in begun if lo != 0)  # none left running when the error came
    if MANY:
        assert 1 <= len(done) <= 3  # the helper ran pieces meanwhile, and took none of the other 4 after the error


def test_the_first_error_is_raised_whichever_thread_it_came_on():
    def run(lo, hi):
        if lo == 0:
            threading.Event().wait(0.2)
            raise ValueError("the caller's, later")
        raise KeyError("a helper's, first")

    with pytest.raises(KeyError if MANY else ValueError):
        _with_threads(2, lambda: over_threads(2, run))


@numba.njit(nogil=True)
def _scaled(lo, hi, x, k, out):
    for i in range(lo, hi):
        out[i] = k * x[i]


def test_a_compiled_kernel_is_typed_once_and_its_pieces_call_its_entry_point(monkeypatch):
    import numerics.threads as threads

    x = np.random.default_rng(1).random(1000)
    out = np.full(1000, np.nan)
    entry = compiled(_scaled, (x, 3.0, out))
    assert entry is _scaled.get_overload(_scaled.signatures[0])  # one signature: its entry point
    pieces = []

    def spied(kernel, args):  # the pieces must call what compiled gives, not the dispatcher
        chosen = compiled(kernel, args)
        assert chosen is entry

        def call(lo, hi, *rest):
            pieces.append(lo)
            chosen(lo, hi, *rest)
        return call

    monkeypatch.setattr(threads, "compiled", spied)
    _with_threads(2, lambda: over_threads(1000, _scaled, x, 3.0, out))
    assert np.array_equal(out, 3.0 * x)
    if MANY:
        assert sorted(pieces) == [1000 * k // len(pieces) for k in range(len(pieces))] and len(pieces) == PIECES * 2
    _scaled(0, 1, x.astype(np.float32), 3.0, out.astype(np.float32))  # a second signature
    assert compiled(_scaled, (x, 3.0, out)) is _scaled  # which one the dispatcher took is not told: itself


def test_callers_on_several_threads_share_the_helpers_while_the_pool_grows():
    # numba's thread count is per thread: callers asking for more helpers than the pool has
    # replace it with a bigger one while others hand ranges over, and no range may fail
    # (handed to a pool shut down) or be lost
    from concurrent.futures import wait

    failures, totals = [], {}

    def caller(k):
        out = np.zeros(64)

        def run(lo, hi):
            out[lo:hi] = np.arange(lo, hi) * k

        try:
            for trial in range(30):
                helpers = 1 + (k + trial) % 8
                cuts = [64 * j // (helpers + 1) for j in range(helpers + 2)]
                ranges = iter(list(zip(cuts[1:-1], cuts[2:])))  # one a helper: next() hands each out once
                futures = HELPERS.submit(lambda r=ranges: run(*next(r)), helpers)
                run(cuts[0], cuts[1])
                wait(futures)
                for f in futures:
                    f.result()
            totals[k] = out.sum()
        except BaseException as exc:  # noqa: BLE001 - the test reports any failure below
            failures.append(exc)

    for _ in range(5):
        HELPERS.reset()  # a fresh pool, grown by the callers as they come
        threads = [threading.Thread(target=caller, args=(k,)) for k in range(8)]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        assert failures == []
        assert totals == {k: k * 2016.0 for k in range(8)}
    _with_threads(2, lambda: over_threads(8, lambda lo, hi: None))  # and over_threads goes on with it


def test_a_range_that_runs_over_threads_again_does_not_hang():
    seen = np.zeros(16, int)
    lock = threading.Lock()

    def inner(lo, hi):
        with lock:
            seen[lo:hi] += 1

    def outer(lo, hi):
        over_threads(16, inner)  # runs in the range's own thread

    assert _in_time(lambda: _with_threads(2, lambda: over_threads(4, outer)))
    threads = min(2, numba.config.NUMBA_NUM_THREADS)
    assert (seen == (min(4, PIECES * threads) if threads > 1 else 1)).all()  # one inner loop per piece of outer


@pytest.mark.skipif(not hasattr(os, "fork"), reason="no fork on this system")
@needs_two
def test_a_forked_child_starts_helpers_of_its_own():
    _with_threads(2, lambda: over_threads(4, lambda lo, hi: None))  # the parent's pool exists
    pid = os.fork()
    if pid == 0:  # the child: its ranges must run (the parent's threads are not there)
        code = 1
        try:
            out = np.zeros(4)

            def run(lo, hi):
                out[lo:hi] = 1.0

            _with_threads(2, lambda: over_threads(4, run))
            code = 0 if out.sum() == 4.0 else 1
        finally:
            os._exit(code)
    waited = []
    assert _in_time(lambda: waited.append(os.waitpid(pid, 0)))
    assert os.waitstatus_to_exitcode(waited[0][1]) == 0


def test_the_time_in_ranges_is_counted_for_the_calling_thread():
    before = time_in_ranges()
    _with_threads(2, lambda: over_threads(2, lambda lo, hi: threading.Event().wait(0.05)))
    spent = time_in_ranges() - before
    assert 0.05 <= spent < 1.0
    other = []
    t = threading.Thread(target=lambda: other.append(time_in_ranges()))
    t.start()
    t.join()
    assert other == [0.0]  # each thread its own clock
