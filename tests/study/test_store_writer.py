"""A study's finished batches are stored on a thread of their own (Store.writer): in the
order they come, in one group when they come faster than the disk takes them, every batch
handed over kept when the run fails, and a failure to store raised where batches are
handed over."""
import errno
import threading
from pathlib import Path

import numpy as np
import pytest

from rig.study.batch import BatchResult
from rig.study.distributions import parse_vary
from rig.study.mc_spec import OUTPUTS
from rig.study.montecarlo import MonteCarloStudy
from rig.study.store import Store

BATCH = 4


def _study():
    return MonteCarloStudy("ptfe52_magnetic", tuple(parse_vary(["striker.velocity=normal(0.89 m/s, 0.01 m/s)"])),
                           6 * BATCH, batch=BATCH)


def _result(b: int) -> BatchResult:
    """Batch b as a study stores it, with numbers that tell the shots apart."""
    index = np.arange(b * BATCH, (b + 1) * BATCH)
    outputs = {k: index * 0.5 + j for j, k in enumerate(OUTPUTS)}
    outputs["failure"] = (index % 3 == 0).astype(float)
    return BatchResult(b, index, 0.89 + 1e-3 * index[:, None], index.astype(np.int64) * 7, outputs)


def test_batches_that_come_faster_than_the_disk_are_stored_as_one_group(tmp_path):
    store = Store(tmp_path / "s", _study()).open()
    groups, real = [], store.write_all
    store.write_all = lambda results: (groups.append([r.batch for r in results]), real(results))
    first_stored, go_on = threading.Event(), threading.Event()

    def stored(result):
        first_stored.set()
        go_on.wait(10)  # the writer is held here while batches 1..3 come in

    with store.writer(stored) as writer:
        writer.put(_result(0))
        assert first_stored.wait(10)
        for b in (1, 2, 3):
            writer.put(_result(b))
        go_on.set()
    assert groups == [[0], [1, 2, 3]]
    assert store.done() == {0, 1, 2, 3}
    got = store.collect()
    assert np.array_equal(got.index, np.arange(4 * BATCH))
    assert np.array_equal(got.seeds, np.arange(4 * BATCH) * 7)
    for k in OUTPUTS:
        assert np.array_equal(got.outputs[k], np.concatenate([_result(b).outputs[k] for b in range(4)])), k


def test_a_failed_run_keeps_every_batch_it_handed_over(tmp_path):
    store = Store(tmp_path / "s", _study()).open()
    told = []
    with pytest.raises(RuntimeError, match="a worker failed"), \
            store.writer(lambda result: told.append(result.batch)) as writer:
        for b in (2, 0, 5):
            writer.put(_result(b))
        raise RuntimeError("a worker failed")
    assert store.done() == {0, 2, 5} and sorted(told) == [0, 2, 5]


def test_a_full_disk_stops_the_writer_and_is_raised_where_batches_are_handed_over(tmp_path, monkeypatch):
    store = Store(tmp_path / "s", _study()).open()
    real, calls = Path.write_bytes, []

    def full_after_one(self, data):
        calls.append(self)
        if len(calls) > 1:
            raise OSError(errno.ENOSPC, "No space left on device")
        return real(self, data)

    monkeypatch.setattr(Path, "write_bytes", full_after_one)
    stored = threading.Event()
    with pytest.raises(OSError) as failure, store.writer(lambda result: stored.set()) as writer:
        writer.put(_result(0))
        assert stored.wait(10)
        writer.put(_result(1))  # the disk is full now: the writer stops
        writer.thread.join(10)
        writer.put(_result(2))  # raised here, not stored
    assert failure.value.errno == errno.ENOSPC and "batch_000001.h5" in str(failure.value)
    assert store.done() == {0}
    assert sorted(p.name for p in store.batches.iterdir()) == ["batch_000000.h5"]  # no temporary left
