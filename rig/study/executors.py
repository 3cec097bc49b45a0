"""Where a study's batches run: in this process, in a pool of local processes, or on a Dask
cluster (optional extra: pip install ".[dask]"). Batches are the same whatever runs them,
so the results are identical; each finished batch is stored at once."""
from __future__ import annotations

import concurrent.futures as cf
import multiprocessing

from rig.errors import RigError
from rig.study.batch import run_batch
from rig.study.mc_spec import Study
from rig.study.store import Store


def _one_thread():
    import numba

    numba.set_num_threads(1)  # the workers share the cores among themselves


def run_study(study: Study, store: Store, workers: int = 1, scheduler: str | None = None,
              progress=None) -> int:
    """Run the batches not yet stored; returns how many batches ran."""
    todo = [b for b in range(study.n_batches) if b not in store.done()]
    tick = progress or (lambda n: None)
    if scheduler:
        return _dask(study, store, todo, scheduler, workers, tick)
    if workers <= 1:
        for b in todo:
            store.write(run_batch(study, b))
            tick(len(study.shots_of(b)))
        return len(todo)
    ctx = multiprocessing.get_context("spawn")  # numba's threads and fork do not mix
    with cf.ProcessPoolExecutor(workers, mp_context=ctx, initializer=_one_thread) as pool:
        futures = {pool.submit(run_batch, study, b): b for b in todo}
        try:
            for fut in cf.as_completed(futures):
                store.write(fut.result())
                tick(len(study.shots_of(futures[fut])))
        except BaseException:
            for fut in futures:
                fut.cancel()
            raise
    return len(todo)


def _dask(study, store, todo, scheduler, workers, tick):
    try:
        from dask.distributed import Client, LocalCluster, as_completed
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
    try:
        futures = [client.submit(run_batch, study, b, pure=False) for b in todo]
        for fut in as_completed(futures):
            result = fut.result()
            store.write(result)
            tick(len(result.index))
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
    return len(todo)
