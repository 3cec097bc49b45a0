"""One study protocol: the executor runs any spec with batches() and run_batch(b) into any
store with done() and writer(); the Monte Carlo study and the sweep are two such specs."""
import contextlib
from dataclasses import dataclass

from rig.study.batch import BatchResult
from rig.study.executors import run_study
from rig.study.montecarlo import MonteCarloStudy
from rig.study.sweep import Sweep, SweepPoint, SweepStore


@dataclass(frozen=True)
class Squares:
    """A study of no physics: batch b holds the squares of b*size .. b*size + size - 1."""

    n: int
    size: int

    def batches(self) -> range:
        return range(-(-self.n // self.size))

    def run_batch(self, b: int) -> "Squares.Batch":
        return Squares.Batch(b, tuple(i * i for i in range(b * self.size, min(self.n, (b + 1) * self.size))))

    @dataclass(frozen=True)
    class Batch:
        batch: int
        values: tuple

        @property
        def shots(self) -> int:
            return len(self.values)


class Memory:
    def __init__(self, kept=None):
        self.kept = dict(kept or {})

    def done(self) -> set:
        return set(self.kept)

    @contextlib.contextmanager
    def writer(self, stored=None):
        store = self

        class Sink:
            def put(self, result):
                store.kept[result.batch] = result
                (stored or (lambda r: None))(result)

        yield Sink()


def test_the_executor_runs_a_study_it_has_never_heard_of_and_resumes_it():
    ticks = []
    store = Memory()
    assert run_study(Squares(10, 4), store, progress=ticks.append) == 3
    assert ticks == [4, 4, 2]  # each batch's shots, once stored
    assert [v for b in sorted(store.kept) for v in store.kept[b].values] == [i * i for i in range(10)]
    resumed = Memory({1: store.kept[1]})
    assert run_study(Squares(10, 4), resumed, progress=ticks.append) == 2  # only the batches not held
    assert resumed.kept == store.kept


def test_the_monte_carlo_study_and_the_sweep_have_the_protocol_s_shape():
    for spec in (MonteCarloStudy, Sweep):
        assert callable(spec.batches) and callable(spec.run_batch)
    assert BatchResult(3, *([()] * 4)).batch == 3
    assert SweepPoint(0.5, None, None, None, "why", 7, batch=2).shots == 1
    store = SweepStore()
    with store.writer() as sink:
        for b in (1, 0):
            sink.put(SweepPoint(float(b), None, None, None, "no record", b, batch=b))
    assert store.done() == {0, 1} and [p.value for p in store.points] == [0.0, 1.0]  # in the sweep's order


def test_the_study_rig_mc_describes_keeps_a_resumed_study_s_batches_and_sizes_a_sobol_design(tmp_path):
    import json

    from rig.study.mc_run import described
    from rig.study.mc_spec import DEFAULT_BATCH
    from rig.study.sobol import sobol_shots

    vary = ["striker.velocity=normal(0.89 m/s, 0.01 m/s)", "gauges.upper.gain=normal(1, 0.01)"]
    fresh = described("ptfe52_magnetic", vary, 40, tmp_path / "new", seed=3)
    assert (fresh.shots, fresh.batch, fresh.seed, fresh.keys) == (40, DEFAULT_BATCH, 3, ["striker.velocity",
                                                                                       "gauges.upper.gain"])
    (tmp_path / "old").mkdir()
    (tmp_path / "old" / "study.json").write_text(json.dumps({"batch": 7}))
    assert described("ptfe52_magnetic", vary, 40, tmp_path / "old").batch == 7  # resumed: its own batches
    assert described("ptfe52_magnetic", vary, 40, tmp_path / "old", batch=5).batch == 5  # --batch says otherwise
    # in one process on many threads: 128 shots per thread, 256 at least, 4096 at most, and no more than the
    # memory limit takes at the study's estimate of a shot held (so that the default is never refused); a
    # resumed study its own
    from rig.solver.estimate import LIMIT_BYTES
    from rig.study.mc_run import cost, held_per_shot

    assert [described("ptfe52_magnetic", vary, 40, tmp_path / "new", threads=n).batch
            for n in (1, 2, 3, 16)] == [256, 256, 384, 2048]
    for truth in (False, True):  # --truth: each shot's whole solution held (a batch of rigs)
        many = described("ptfe52_magnetic", vary, 10**6, tmp_path / "new", threads=64, truth=truth)
        assert many.batch == max(256, min(4096, int(LIMIT_BYTES // held_per_shot(many).bytes)))
        assert 256 <= many.batch < 4096 and cost(many).bytes <= LIMIT_BYTES
    assert described("ptfe52_magnetic", vary, 40, tmp_path / "old", threads=16).batch == 7
    sobol = described("ptfe52_magnetic", vary, 40, tmp_path / "new", sobol=True)
    assert sobol.shots == sobol_shots(40, 2) == 32 and sobol.sobol  # whole base samples of 2 + 2 shots
