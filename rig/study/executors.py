"""Where a study's batches run: in this process, in a pool of local processes, or on a Dask
cluster (optional extra: pip install ".[dask]"), for any study (rig/study/protocol.py: a
StudySpec and its StudyStore; the Monte Carlo study, the sweep). Batches are the same
whatever runs them, so the results are identical; each finished batch goes at once to the
store's writer (the Monte Carlo store's: a thread of its own), so the loop that feeds the
workers never waits on the disk."""
from __future__ import annotations

import concurrent.futures as cf
import contextlib
import multiprocessing
import os
import queue

from rig.errors import RigError
from rig.study.protocol import StudySpec, StudyStore

PR_SET_PDEATHSIG = 1  # linux/prctl.h
DEFAULT_WORKER_TIMEOUT = 300.0  # s without any live Dask worker before a study stops
POLL_S = 1.0  # how often a Dask study looks at its workers while it waits (s)


def _worker_start(parent: int):
    """A local worker: one numba thread (the workers share the cores among themselves),
    and on Linux killed with its parent, so that a killed study leaves no orphan."""
    import numba

    die_with_parent(parent)
    numba.set_num_threads(1)


def die_with_parent(parent: int):
    """Ask Linux to SIGKILL this process when its parent dies (prctl PR_SET_PDEATHSIG);
    exit at once if the parent ``parent`` is already gone. Elsewhere: nothing."""
    import signal
    import sys

    if not sys.platform.startswith("linux"):
        return
    import ctypes

    ctypes.CDLL(None, use_errno=True).prctl(PR_SET_PDEATHSIG, int(signal.SIGKILL), 0, 0, 0)
    if os.getppid() != parent:
        os._exit(1)


class WorkerWatch:
    """Stops a study that has had no live worker for ``timeout`` seconds: ``check(n)`` is
    told how many workers are alive now; ``clock`` gives seconds (monotonic)."""

    def __init__(self, timeout: float, clock=None):
        import time

        self.timeout = timeout
        self.clock = clock or time.monotonic
        self.since: float | None = None

    def seen(self):
        """A worker just delivered a batch: it is alive."""
        self.since = None

    def check(self, workers: int, kept: int):
        """RigError when no worker has been alive for the timeout (``kept``: batches stored)."""
        if workers:
            self.seen()
            return
        now = self.clock()
        self.since = now if self.since is None else self.since
        if now - self.since >= self.timeout:
            raise RigError(f"--scheduler: no Dask worker alive for {self.timeout:g} s (--worker-timeout); "
                           f"{kept} finished batches are kept: run the same command again to resume")


def run_study(study: StudySpec, store: StudyStore, workers: int = 1, scheduler: str | None = None,
              progress=None, worker_timeout: float = DEFAULT_WORKER_TIMEOUT) -> int:
    """Run the batches of ``study`` that ``store`` does not hold yet; returns how many
    batches ran. ``progress(n)`` is told the shots of each batch once it is stored. The
    batches go to the store's writer as they finish (the Monte Carlo store's writes on a
    thread of its own, so that neither the workers nor this loop wait on the disk). On Dask,
    a study with no live worker for ``worker_timeout`` seconds stops (RigError)."""
    todo = [b for b in study.batches() if b not in store.done()]
    tick = progress or (lambda n: None)
    with store.writer(lambda result: tick(result.shots)) as writer:
        if scheduler:
            _dask(study, store, todo, scheduler, workers, writer, WorkerWatch(worker_timeout))
        elif workers <= 1:
            for b in todo:
                writer.put(study.run_batch(b))
        else:
            _local_pool(study, todo, workers, writer)
    return len(todo)


def _local_pool(study: StudySpec, todo: list, workers: int, writer):
    ctx = multiprocessing.get_context("spawn")  # numba's threads and fork do not mix
    with cf.ProcessPoolExecutor(workers, mp_context=ctx, initializer=_worker_start,
                                initargs=(os.getpid(),)) as pool:
        futures = [pool.submit(study.run_batch, b) for b in todo]
        try:
            for fut in cf.as_completed(futures):
                writer.put(fut.result())
        except BaseException:
            for fut in futures:
                fut.cancel()
            raise


def run_batch_alone(study: StudySpec, b: int):
    """Batch b on one numba thread: what a Dask task runs. Dask runs one task per worker
    thread; numba's own threads (one per core by default) in every worker would put
    workers x cores threads on the cores."""
    import numba

    numba.set_num_threads(1)  # this thread's (numba's thread count is per calling thread)
    return study.run_batch(b)


def _dask(study, store, todo, scheduler, workers, writer, watch: WorkerWatch):
    try:
        from dask.distributed import Client, LocalCluster
    except ImportError:
        raise RigError('--scheduler needs Dask: pip install ".[dask]"') from None
    if scheduler == "local":
        cluster = LocalCluster(n_workers=max(1, workers), threads_per_worker=1, processes=True,
                               dashboard_address=None)
        client = Client(cluster)
    else:
        cluster = None
        try:
            client = Client(scheduler, timeout=10)
        except OSError as exc:
            raise RigError(f"--scheduler {scheduler}: no Dask scheduler answers there ({exc})") from None
        except ValueError as exc:  # an address Dask cannot read: no port, an unknown scheme
            raise RigError(f"--scheduler = {scheduler!r}: allowed 'local' or a scheduler's address such as "
                           f"tcp://HOST:PORT ({exc})") from None
    try:
        # each future once it is done (Dask calls back on a thread of its own)
        finished: queue.SimpleQueue = queue.SimpleQueue()
        futures = [client.submit(run_batch_alone, study, b, pure=False) for b in todo]
        for fut in futures:
            fut.add_done_callback(finished.put)
        left = len(futures)
        while left:
            try:
                done = [finished.get(timeout=POLL_S)]
            except queue.Empty:  # nothing finished in this poll: is any worker alive?
                watch.check(len(client.scheduler_info()["workers"]), len(store.done()))
                continue
            with contextlib.suppress(queue.Empty):
                while True:
                    done.append(finished.get_nowait())
            for result in client.gather(done):  # one round trip for every batch finished meanwhile
                writer.put(result)
            left -= len(done)
            watch.seen()
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
