"""Where a Monte Carlo study keeps its work: DIR/study.json (the study), DIR/batches/
batch_NNNNNN.h5 (one per finished batch), for a study with traces DIR/traces/
batch_NNNNNN.h5 (a shot archive per batch, written before the batch counts as finished),
and at the end DIR/study.h5. Every file appears whole or not at all (instruments.files), so
a killed or failed run can always be resumed by running it again. Finished batches are
written on a thread of their own (``Store.writer``), in groups when they come faster than
the disk takes them: the run's loop hands a batch over and goes back to its workers, and a
group of k batches costs k file syncs and one sync of the folder, not 2k. DIR/study.lock is held by
the run that writes the folder (``Store.held``): a second run into it is refused. A run
that fails before its first batch is stored leaves the folder as it found it (no
study.json, no folder it created); one that stored batches keeps them, and the same
command resumes. A failed run removes the lock file it created."""
from __future__ import annotations

import contextlib
import json
import queue
import threading
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from instruments.files import atomic_writes, folder_lock, hdf5_image, left_as_found, write_hdf5, write_text
from rig.errors import RigError
from rig.study.batch import BatchResult
from rig.study.mc_spec import OUTPUTS, MonteCarloSpec


@dataclass(frozen=True, eq=False)
class StudyResults:
    """Every finished shot, in shot order: index, inputs (shots, K), seeds, outputs."""

    index: np.ndarray
    inputs: np.ndarray
    seeds: np.ndarray
    outputs: dict


class Store:
    """The study's folder (see the module's docstring): a Monte Carlo study's StudyStore
    (rig/study/protocol.py)."""

    def __init__(self, folder, study: MonteCarloSpec):
        self.folder = Path(folder)
        self.study = study
        self.batches = self.folder / "batches"
        self.traces = self.folder / "traces"

    @staticmethod
    def stored_batch(folder) -> int | None:
        """The batch size of the study in ``folder`` (DIR/study.json), or None where there is
        none (or it cannot be read: Store.open then says why)."""
        try:
            batch = json.loads((Path(folder) / "study.json").read_text()).get("batch")
        except (OSError, ValueError, AttributeError):
            return None
        return batch if isinstance(batch, int) and not isinstance(batch, bool) and batch >= 1 else None

    @contextlib.contextmanager
    def held(self):
        """The folder, held by this run for as long as the block runs: another run into it
        (same folder, any study) is refused in one line naming the holder. The OS releases
        the hold when this process ends, killed or not."""
        with (folder_lock(self.folder, "study.lock", "wait for it to end, or give another --out"),
              left_as_found(self.folder, Exception, keep=lambda exc: bool(self.done()))):  # inside the hold
            yield self

    def open(self) -> Store:
        """Create the folder, or check that it holds this very study (to resume it)."""
        meta = self.folder / "study.json"
        spec = {"digest": self.study.digest(), **self.study.spec()}
        fresh = not meta.exists()
        if not fresh:
            try:
                old = json.loads(meta.read_text())
            except (ValueError, OSError) as exc:
                raise RigError(f"{meta}: not a study file ({exc}); give another --out or remove "
                               f"{self.folder}") from None
            if not isinstance(old, dict):
                raise RigError(f"{meta}: not a study file (a JSON {type(old).__name__}, not an object); give "
                               f"another --out or remove {self.folder}")
            if old.get("digest") != spec["digest"]:
                raise RigError(self._other_study(old, spec))
        elif self.batches.exists() and any(self.batches.glob("batch_*.h5")):
            # finished batches without the study they belong to: their shots' sizes and inputs are unknown
            raise RigError(f"{self.folder} holds finished batches but no study.json: they belong to a study that "
                           f"cannot be checked; give another --out or remove {self.folder}")
        self.batches.mkdir(parents=True, exist_ok=True)
        if fresh:
            write_text(meta, json.dumps(spec, indent=1))
        return self

    def _other_study(self, old: dict, spec: dict) -> str:
        """Why ``self.folder``'s study (``old``, from its study.json) is not this one: the
        fields that differ, and what to do."""
        spec = json.loads(json.dumps(spec))  # tuples as JSON has them
        differ = [k for k in spec if k != "digest" and old.get(k) != spec[k]]
        if differ == ["batch"]:
            return (f"{self.folder} holds this study begun with --batch {old.get('batch')!r}; run it with that "
                    f"batch size (or without --batch) to resume it, or give another --out")
        shown = ", ".join(f"{k} {old.get(k)!r} (now {spec[k]!r})" for k in differ[:3]) or "its digest"
        return (f"{self.folder} holds another study ({shown}{', ...' if len(differ) > 3 else ''}); give "
                f"another --out or remove {self.folder}")

    def done(self) -> set:
        return {int(p.stem.split("_")[1]) for p in self.batches.glob("batch_*.h5")}

    def write(self, result: BatchResult):
        """Store one finished batch (its file appears whole or not at all)."""
        self.write_all([result])

    def write_all(self, results: list):
        """Store finished batches: each one's trace archive first (where the study keeps
        traces), then every batch file, all written and synced before any is renamed into
        DIR/batches/ and the folder synced once."""
        for result in results:
            if result.traces:
                from instruments.archive import Archive

                self.traces.mkdir(exist_ok=True)
                archive = self.traces / f"batch_{result.batch:06d}.h5"
                archive.unlink(missing_ok=True)  # left by an interrupted run: that batch did not finish
                Archive(archive).append(list(result.traces))
        atomic_writes({self.batches / f"batch_{r.batch:06d}.h5": _batch_file(r) for r in results})

    @contextlib.contextmanager
    def writer(self, stored=None, backlog: int = 64):
        """A ``BatchWriter`` storing the batches handed to it on a thread of its own;
        ``stored(result)`` is told each batch once it is on disk (on that thread). On
        leaving the block every batch handed over is stored; where the block fails, the
        batches already handed over are stored too (finished work kept), then the failure
        goes on."""
        batch_writer = BatchWriter(self, stored or (lambda result: None), backlog)
        try:
            yield batch_writer
        finally:
            batch_writer.close()

    def collect(self) -> StudyResults:
        """Every finished shot, in shot order."""
        import h5py

        parts = []
        for p in sorted(self.batches.glob("batch_*.h5")):
            with h5py.File(p, "r") as f:
                parts.append({"index": f["index"][()], "inputs": f["inputs"][()], "seeds": f["seeds"][()],
                              "outputs": {k: f[f"outputs/{k}"][()] for k in f["outputs"]}})
        if not parts:
            return StudyResults(np.zeros(0, int), np.zeros((0, len(self.study.keys))), np.zeros(0, np.int64),
                                {k: np.zeros(0) for k in OUTPUTS})
        order = np.argsort(np.concatenate([q["index"] for q in parts]))
        def cat(key):
            return np.concatenate([q[key] for q in parts])[order]
        return StudyResults(cat("index"), cat("inputs"), cat("seeds"),
                            {k: np.concatenate([_output(q, k) for q in parts])[order] for k in OUTPUTS})

    def consolidate(self, results: StudyResults, report: dict) -> Path:
        """DIR/study.h5: every shot's inputs, outputs and seed, and the report."""
        def write(f):
            f.attrs["study"] = json.dumps(self.study.spec())
            f.attrs["report"] = json.dumps(report, default=float)
            f["shot"] = results.index
            f["seed"] = results.seeds
            f["seed"].attrs["description"] = ("instrument seed; inputs come from SeedSequence(study seed, "
                                              "spawn_key=(shot,))")
            for k, key in enumerate(self.study.keys):
                f[f"inputs/{key}"] = results.inputs[:, k]
            for k, v in results.outputs.items():
                f[f"outputs/{k}"] = v

        return write_hdf5(self.folder / "study.h5", write)


def _batch_file(result: BatchResult):
    """What writes batch ``result``'s file (DIR/batches/batch_NNNNNN.h5) to a path."""
    def fill(f):
        f["index"] = result.index
        f["inputs"] = result.inputs
        f["seeds"] = result.seeds
        for k, v in result.outputs.items():
            f[f"outputs/{k}"] = v

    return lambda path: Path(path).write_bytes(hdf5_image(fill)[0])


class BatchWriter:
    """Stores finished batches on a thread of its own (``Store.writer``), in the order they
    are handed over, each time every batch waiting (a group: one folder sync for all). At
    most ``backlog`` batches wait; ``put`` waits beyond that. A failure to store (a full
    disk) or in ``stored`` stops the writer: the batches still waiting are not stored, and
    the failure is raised in the thread that hands batches over, at its next ``put`` or at
    ``close``."""

    STOP = None

    def __init__(self, store: Store, stored, backlog: int):
        self.store, self.stored = store, stored
        self.waiting: queue.Queue = queue.Queue(backlog)
        self.failure: BaseException | None = None
        self.thread = threading.Thread(target=self._run, name="rig-study-store", daemon=True)
        self.thread.start()

    def put(self, result: BatchResult):
        """Hand batch ``result`` over to be stored."""
        self._raise_failure()
        while self.thread.is_alive():
            try:
                self.waiting.put(result, timeout=0.1)
                return
            except queue.Full:
                continue
        self._raise_failure()

    def close(self):
        """Store every batch handed over, stop the thread; raise a failure it met."""
        if self.thread.is_alive():
            self.waiting.put(self.STOP)
            self.thread.join()
        self._raise_failure()

    def _raise_failure(self):
        if self.failure is not None:
            failure, self.failure = self.failure, None
            raise failure

    def _run(self):
        while True:
            group = [self.waiting.get()]
            with contextlib.suppress(queue.Empty):
                while group[-1] is not self.STOP:
                    group.append(self.waiting.get_nowait())
            results = [r for r in group if r is not self.STOP]
            try:
                if results:
                    self.store.write_all(results)
                for result in results:
                    self.stored(result)
            except BaseException as exc:  # noqa: BLE001 (KeyboardInterrupt too): raised where batches are handed over
                self.failure = exc
                return
            if len(results) < len(group):
                return


def _output(part: dict, key: str) -> np.ndarray:
    """One output of a stored batch; a batch stored before shots could fail has no "failure"."""
    if key == "failure" and key not in part["outputs"]:
        return np.zeros(part["index"].size)
    return part["outputs"][key]
