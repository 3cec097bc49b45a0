"""Sweeps: one virtual shot per value of a scene key (`rig sweep`).

Every point's rig is assembled before any shot is fired, so a bad key, a value outside
its range or an impossible sweep is refused with nothing fired. Seeds come from one
numpy SeedSequence (the sweep's seed) so that any point can be fired again alone. A
sweep is a study (rig/study/protocol.py): one batch per point, run by the study executor
and kept by a SweepStore.
"""
from __future__ import annotations

import contextlib
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from rig.errors import RigError, invalid
from rig.experiment.entry import shot_entry
from rig.experiment.measure import shot_blocks
from rig.experiment.scene import schema_node
from rig.experiment.shot import Rig, ShotRecord
from rig.study.executors import run_study
from rig.units import typed_quantity, whole


@dataclass(frozen=True)
class Vary:
    """KEY=START:STOP:COUNT, evenly spaced, START <= STOP, COUNT >= 1 (quantities in SI or
    with units)."""

    key: str
    values: tuple

    @classmethod
    def parse(cls, text: str, max_count: int | None = None) -> Vary:
        """Parse KEY=START:STOP:COUNT; more than ``max_count`` points (if given) is refused
        before any is made."""
        if "=" not in text:
            raise invalid("--vary", text, "expected KEY=START:STOP:COUNT, e.g. striker.velocity=0.3:1.5:7")
        key, spec = (s.strip() for s in text.split("=", 1))
        parts = spec.split(":")
        if len(parts) != 3:
            raise invalid("--vary", text, "expected KEY=START:STOP:COUNT")
        unit = _unit_of(key)
        start, stop = (typed_quantity(p, unit, f"--vary {key}") for p in parts[:2])
        count = whole(parts[2], f"--vary {key} COUNT", "a whole number >= 1")
        if count < 1:
            raise invalid(f"--vary {key} COUNT", count, "a whole number >= 1")
        if max_count is not None and count > max_count:
            raise invalid(f"--vary {key} COUNT", count, f"at most {max_count} points; add --allow-large for more")
        if start > stop:
            raise invalid(f"--vary {key}", spec, "START must not exceed STOP")
        if count == 1 and start != stop:
            raise invalid(f"--vary {key}", spec, "one point needs START = STOP")
        values = tuple(float(v) for v in np.linspace(start, stop, count))
        if schema_node(key) is int:  # chain.beads, gauges.NAME.bead, scope.record_length
            off = [v for v in values if abs(v - round(v)) > 1e-9 * max(1.0, abs(v))]
            if off:
                raise invalid(f"--vary {key}", spec, f"a whole-number key, and the point {off[0]:g} is not whole: "
                                                     "choose START, STOP and COUNT that give whole numbers")
            values = tuple(float(round(v)) for v in values)
        return cls(key, values)

    def override(self, value) -> str:
        """The --set text of one point."""
        unit = _unit_of(self.key)
        if unit is None:
            return f"{self.key}={int(value) if schema_node(self.key) is int else value!r}"
        return f"{self.key}={value!r} {unit}"


def _unit_of(key: str):
    try:
        node = schema_node(key)
    except KeyError:
        raise invalid("--vary", key, "unknown scene key") from None
    if isinstance(node, dict):
        raise invalid("--vary", key, "is a table; vary one of its keys")
    if node in (float, int):
        return None
    if not isinstance(node, str):
        raise invalid("--vary", key, "only numeric keys can be swept")
    return node


@dataclass(frozen=True, eq=False)
class SweepPoint:
    """One point of a sweep: its shot and figures, or (shot None) why it gave no record and
    the seed it was fired with (the same scene, overrides and seed fire it again alone);
    ``batch``: its number in the sweep (a sweep's batch is one point: a StudyBatch of
    rig/study/protocol.py)."""

    value: float
    rig: Rig
    shot: ShotRecord | None
    blocks: dict | None
    reason: str | None = None
    seed: int | None = None
    batch: int = 0

    @property
    def shots(self) -> int:
        return 1


def seeds_for(seed: int, count: int) -> list:
    """count reproducible 63-bit seeds from one SeedSequence."""
    state = np.random.SeedSequence(seed).generate_state(count, np.uint64)
    return [int(s >> np.uint64(1)) for s in state]


@dataclass(frozen=True, eq=False)
class Sweep:
    """A sweep as a study (a StudySpec of rig/study/protocol.py): point b, batch b, is the
    shot of ``rigs[b]`` (assembled and checked, for ``vary.values[b]``) fired with
    ``seeds[b]``."""

    vary: Vary
    rigs: tuple
    seeds: tuple

    @classmethod
    def of(cls, scene, vary: Vary, overrides=(), seed: int = 0) -> Sweep:
        """Every point's rig assembled (validated) before any is fired: a bad key, a value
        outside its range or an impossible point is refused (RigError naming the point)."""
        rigs = []
        for v in vary.values:
            try:
                rigs.append(Rig.from_scene(scene, list(overrides) + [vary.override(v)]))
                rigs[-1].check_record()
            except ValueError as exc:
                raise RigError(f"--vary {vary.key} = {v:g}: {exc}") from None
        return cls(vary, tuple(rigs), tuple(seeds_for(seed, len(rigs))))

    def batches(self) -> range:
        return range(len(self.rigs))

    def run_batch(self, b: int) -> SweepPoint:
        """Point b: its shot and figures; a point that fires but gives no record (the solver
        or the scope refuses it: a RigError raised by the shot) is a point with its reason."""
        v, rig, s = self.vary.values[b], self.rigs[b], self.seeds[b]
        try:
            shot = rig.fire(seed=s)
        except RigError as exc:
            return SweepPoint(v, rig, None, None, str(exc), s, b)
        return SweepPoint(v, rig, shot, shot_blocks(rig, shot), batch=b)


class SweepStore:
    """Where a sweep keeps its points (a StudyStore of rig/study/protocol.py): in memory, and
    the shots that gave a record appended to ``archive`` (if any) in one transaction when
    the writer's block ends, interrupted or not."""

    def __init__(self, archive=None):
        self.archive = archive
        self.kept = {}  # point number -> SweepPoint

    def done(self) -> set:
        return set(self.kept)

    @property
    def points(self) -> list:
        """The points kept, in the sweep's order."""
        return [self.kept[b] for b in sorted(self.kept)]

    @contextlib.contextmanager
    def writer(self, stored=None):
        """The BatchSink of the block; ``stored(point)`` is told each point kept."""
        entries: list = []  # the archive entries of the points kept, appended once at the end
        try:
            yield _Collector(self, entries, stored or (lambda point: None))
        finally:
            if self.archive is not None and entries:
                from instruments.archive import Archive

                Archive(self.archive).append(entries)


@dataclass(frozen=True)
class _Collector:
    """A SweepStore's writer: each point kept, the archive Entry of each shot gathered."""

    store: SweepStore
    entries: list
    stored: Callable

    def put(self, point: SweepPoint) -> None:
        self.store.kept[point.batch] = point
        if point.shot is not None:
            self.entries.append(shot_entry(point.shot))
        self.stored(point)


def run_sweep(scene, vary: Vary, overrides=(), seed: int = 0, progress=None, archive=None) -> list:
    """Fire one shot per value (``Sweep``, on the study executor, in this process); archive
    those that gave a record (if an archive is given), even when the sweep is interrupted.
    ``progress()`` is told each point fired. A point that gives no record is a point with
    its reason, and the sweep goes on to the next value."""
    store = SweepStore(archive)
    run_study(Sweep.of(scene, vary, overrides, seed), store, progress=progress and (lambda n: progress()))
    return store.points
