"""What a Monte Carlo study is (`rig mc`): a scene, its fixed overrides, the uncertain
inputs, the number of shots, one seed, the batch size and what to record. Shot i always
belongs to batch i // batch and draws its inputs from child i of the study's numpy
SeedSequence, so results depend on none of the executor, the workers or the order."""
from __future__ import annotations

import enum
import hashlib
import json
import math
from dataclasses import asdict, dataclass

from rig.errors import invalid
from rig.study.distributions import Distribution
from rig.units import MAX_SEED, is_whole

WINDOWS = ("leading", "record")
OUTPUTS = ("speed_m_per_s", "speed_xcorr_m_per_s", "amplitude_N", "averaged_amplitude_N",
           "truth_speed_m_per_s", "truth_amplitude_N", "energy_error", "dt_s", "failure")


class Failure(enum.IntEnum):
    """Why a shot gave no result: its "failure" output is this code (NONE: it did not fail).
    The codes are stored: a new reason goes at the end, none is ever moved."""

    NONE = 0
    IMPOSSIBLE = 1
    UNSTABLE = 2
    NO_TRIGGER = 3
    SHORT_WINDOW = 4
    NON_FINITE = 5
    CLIPPED = 6

    @property
    def message(self) -> str:
        """The reason as the report names it (report.json's "failed" reasons)."""
        return FAILURES[self]


FAILURES = ("none", "impossible inputs (the rig refuses them)", "solver unstable",
            "the scope did not trigger",
            "the scope record ends after the simulated window (--window record simulates the whole record)",
            "non-finite measured speed or amplitude",
            "a gauge channel clipped (its signal ran off the scope's range: raise scope.channels.CHn.volts_per_div)")
"""Each Failure's message, by code."""


DEFAULT_BATCH = 256  # shots per batch: a batch's fixed costs (threads, arrays) spread over more shots
SHOTS_PER_THREAD = 128  # in one process on many threads: the solver's widest chunk (rig/solver/ensemble.py) each
MAX_BATCH = 4096


def default_batch(threads: int = 1, bytes_per_shot: float = 0.0) -> int:
    """Shots per batch where none is given, for a study run in one process on ``threads``
    numba threads (1: a worker process of many): DEFAULT_BATCH, or SHOTS_PER_THREAD shots
    per thread where that is more, at most MAX_BATCH and as many as the memory limit of a
    run takes (rig.solver.estimate.LIMIT_BYTES) at ``bytes_per_shot`` held a shot (the
    study's estimate: rig.study.mc_run.held_per_shot). The solver integrates a batch's
    shots in chunks of up to 128 shots, one or more per thread; a narrower chunk costs
    more per shot (16 shots: 1.6 times the CPU of 128, from the work each step does per
    chunk), and a batch's fixed costs weigh less. On 16 cores, 2048 shots a batch ran
    about 1.5 to 2 times as many shots/s as 256 (rig bench mc's scaling table). The shots'
    values do not depend on the batch size."""
    from rig.solver.estimate import LIMIT_BYTES

    batch = min(MAX_BATCH, SHOTS_PER_THREAD * threads)
    if bytes_per_shot > 0:
        batch = min(batch, int(LIMIT_BYTES // bytes_per_shot))
    return max(DEFAULT_BATCH, batch)


@dataclass(frozen=True)
class MonteCarloSpec:
    """What a Monte Carlo study is (module doc): its draws, shots and batches. The study
    that runs them, a StudySpec of rig/study/protocol.py, is rig/study/montecarlo.py's
    MonteCarloStudy; the batch code (rig/study/batch.py) reads this spec only."""

    scene: str
    dists: tuple
    shots: int
    seed: int = 0
    overrides: tuple = ()
    batch: int = DEFAULT_BATCH
    accuracy: float | None = None
    sobol: bool = False
    truth: bool = False  # also analyse each shot's noise-free truth (slower)
    window: str = "leading"  # "leading": until the leading pulse is past the last gauge; "record": the scene's
    traces: bool = False  # also archive every shot's scope record and truth (DIR/traces/)

    def __post_init__(self):
        if self.window not in WINDOWS:
            raise invalid("--window", self.window, f"one of {', '.join(WINDOWS)}")
        for field, name, lo, hi, allowed in (("shots", "--shots", 1, 2**32, "a whole number from 1 to 2^32"),
                                             ("seed", "--seed", 0, MAX_SEED, "a whole number from 0 to 2^63 - 1"),
                                             ("batch", "--batch", 1, math.inf, "a whole number >= 1")):
            value = getattr(self, field)
            if not is_whole(value) or not lo <= value <= hi:
                raise invalid(name, value, allowed)
            object.__setattr__(self, field, int(value))  # numpy's integers too, stored as plain ints
        if not all(isinstance(d, Distribution) for d in self.dists):
            raise invalid("dists", self.dists, "Distributions (rig.study.distributions.parse_vary)")
        drawn = set(self.keys) & {o.split("=", 1)[0].strip() for o in self.overrides}
        if drawn:
            raise invalid("--set", ", ".join(sorted(drawn)), "a key that --vary does not draw (give it once)")
        if self.accuracy is not None:  # what solve accepts
            from rig.solver.stepsize import checked_accuracy

            checked_accuracy(self.accuracy, "--accuracy")

    @property
    def keys(self) -> list:
        return [d.key for d in self.dists]

    def spec(self) -> dict:
        return {"scene": str(self.scene), "dists": [asdict(d) for d in self.dists], "shots": self.shots,
                "seed": self.seed, "overrides": list(self.overrides), "batch": self.batch,
                "accuracy": self.accuracy, "sobol": self.sobol, "truth": self.truth, "window": self.window,
                "traces": self.traces}

    def digest(self) -> str:
        return hashlib.sha256(json.dumps(self.spec(), sort_keys=True).encode()).hexdigest()[:16]

    @property
    def n_batches(self) -> int:
        return -(-self.shots // self.batch)

    def batches(self) -> range:
        """Every batch's number (rig/study/protocol.py: a StudySpec)."""
        return range(self.n_batches)

    def shots_of(self, b: int) -> range:
        """The shots of batch b: shot i always belongs to batch i // batch."""
        if not is_whole(b) or not 0 <= b < self.n_batches:
            raise invalid("batch", b, f"a whole number from 0 to {self.n_batches - 1} (the study's batches)")
        return range(b * self.batch, min(self.shots, (b + 1) * self.batch))
