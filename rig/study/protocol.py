"""What any study is to the executors (rig/study/executors.py) and to its store: a spec
cut into numbered batches, each run alone into a finished batch, which the store keeps.

    spec.batches()  ->  spec.run_batch(b)  ->  a StudyBatch  ->  store.writer().put(it)

A batch is the same whoever runs it (this process, a local worker, a Dask worker), so a
spec and its batches must pickle; a store says which batches it already holds (``done``:
a study run again resumes) and takes finished ones on its writer. The Monte Carlo study
(rig/study/montecarlo.py: ``MonteCarloStudy``, its ``BatchResult``, its folder
rig/study/store.py) and the sweep (rig/study/sweep.py: ``Sweep``, a ``SweepPoint`` per
batch, ``SweepStore``) are two such studies; a new one is a spec, a batch and a store of
these shapes, and runs on every executor.
"""
from __future__ import annotations

from collections.abc import Callable
from contextlib import AbstractContextManager
from typing import Protocol


class StudyBatch(Protocol):
    """One finished batch of a study."""

    @property
    def batch(self) -> int:
        """Its number, one of its spec's ``batches()``."""

    @property
    def shots(self) -> int:
        """How many shots it holds (what a progress bar counts)."""


class StudySpec(Protocol):
    """A study: its batches, by number, and how one of them runs."""

    def batches(self) -> range:
        """Every batch's number, in order."""

    def run_batch(self, b: int) -> StudyBatch:
        """Batch b, run in this process; the same result in any process."""


class BatchSink(Protocol):
    """What a store's writer is: it takes finished batches, in the order they finish."""

    def put(self, result: StudyBatch) -> None:
        """Store ``result`` (now, or on a thread of the store's own)."""


class StudyStore(Protocol):
    """Where a study keeps its finished batches."""

    def done(self) -> set:
        """The numbers of the batches it holds already."""

    def writer(self, stored: Callable[[StudyBatch], None] | None = None) -> AbstractContextManager[BatchSink]:
        """A BatchSink for the block; ``stored(result)`` is told each batch once it is kept.
        On leaving the block (even by an exception) every batch put is kept."""
