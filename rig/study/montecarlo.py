"""A Monte Carlo study as the executors run it: the spec (rig/study/mc_spec.py) and how
one of its batches is fired (rig/study/batch.py), a StudySpec of rig/study/protocol.py."""
from __future__ import annotations

from dataclasses import dataclass

from rig.study.batch import BatchResult, run_batch
from rig.study.mc_spec import MonteCarloSpec


@dataclass(frozen=True)
class MonteCarloStudy(MonteCarloSpec):
    """A Monte Carlo study: its batches run on any executor (rig/study/executors.py) and
    are kept in its folder (rig/study/store.py)."""

    def run_batch(self, b: int) -> BatchResult:
        """Batch b's BatchResult: its shots fired, read and analysed."""
        return run_batch(self, b)
