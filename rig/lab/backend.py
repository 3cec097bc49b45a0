"""What lab devices drive: a rig that takes settings and fires shots.

``ShotBackend`` is the small interface the bluesky devices (rig/lab/bluesky.py) are written
against, so that a rig reached over SCPI can stand in for the one in this process:
``set(key, text)`` changes one scene key (a value text with its unit, as in scene files),
``value(key)`` reads it back in SI units, ``fire()`` fires the next shot. ``InProcessBench``
is the in-process one: a scene's ``SceneShots`` and the settings changed so far, the k-th
new shot fired with seed N + k - 1, each shot the bits of ``rig shot SCENE --set ... --seed``.
``fire(seed)`` fires a shot of that sequence again at its own seed (a shot redone: the one a
bluesky pause caught in flight, whose event was never emitted); the sequence does not
advance, so no seed is skipped or given to two different shots. Its calls block (a shot
solves the chain the first time); devices run them off the event loop.
"""
from __future__ import annotations

import threading
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import Protocol

from instruments.errors import InstrumentError
from instruments.records import ScopeRecord
from rig.errors import RigError, invalid
from rig.lab.shots import SceneShots
from rig.units import MAX_SEED


@dataclass(frozen=True)
class Fired:
    """One shot as a backend hands it on: the scope's record, the seed it was fired with
    and the settings changed from the scene as served ("key=value" items, key order)."""

    record: ScopeRecord
    seed: int
    overrides: tuple


class ShotBackend(Protocol):
    """A rig the lab devices drive (in this process, or over SCPI)."""

    channels: tuple
    """The scope's displayed channels, e.g. ("CH1", "CH2", "CH3")."""

    def set(self, key: str, text: str) -> None:
        """Set a scene key (``text``: its value with its unit, e.g. "2.38 N") for the next
        shots; InstrumentError of one line where the rig refuses it (nothing changes)."""

    def value(self, key: str) -> float:
        """The value of a scene key the next shot is fired with (SI units)."""

    def fire(self, seed: int | None = None) -> Fired:
        """Fire a shot and return it (blocks until the record is in): without ``seed`` the
        next shot of the rig's seed sequence; with ``seed``, one the sequence has given
        already, fired again (a shot redone), which does not advance the sequence.
        InstrumentError of one line for a seed the sequence has not given."""


class InProcessBench:
    """The ShotBackend of a scene in this process.

    scene: a published scene's name or a scene file's path; base_overrides: the "key=value"
    items it is served with (as ``rig shot --set``); seed: N, the seed of the first shot.
    RigError here for a bad scene, a base setting or seed; InstrumentError from its calls.

    ``next_seed`` is the seed of the next new shot (N + the new shots fired so far); ``fired``
    counts every shot fired, those redone at their own seed too.
    """

    def __init__(self, scene, base_overrides: Iterable[str] | Mapping[str, str] = (), seed: int = 0):
        if isinstance(seed, bool) or not isinstance(seed, int) or not 0 <= seed <= MAX_SEED:
            raise invalid("seed", seed, f"a whole number from 0 to {MAX_SEED}")
        self.shots = SceneShots(scene, base_overrides)
        self.channels = tuple(self.shots.loaded.values["scope"]["channels"])
        self.first_seed = seed
        self.next_seed = seed
        self.fired = 0
        self.overrides: dict[str, str] = {}
        self._lock = threading.Lock()

    def set(self, key: str, text: str) -> None:
        with self._lock:
            wanted = {**self.overrides, key: text}
            try:
                never = self.shots.rig(wanted).trigger_never_fires()  # the scene read, its parts built
            except RigError as exc:
                raise InstrumentError(str(exc)) from None
            if never is not None:  # refused, as rig shot refuses it
                raise InstrumentError(str(never))
            self.overrides = wanted

    def value(self, key: str) -> float:
        with self._lock:
            node = self.shots.rig(self.overrides).values
        for part in key.split("."):
            if not isinstance(node, dict) or part not in node:
                raise InstrumentError(f"{key}: not set in scene {self.shots.loaded.name}")
            node = node[part]
        if isinstance(node, bool) or not isinstance(node, (int, float)):
            raise InstrumentError(f"{key} = {node!r}: not a number")
        return float(node)

    def fire(self, seed: int | None = None) -> Fired:
        with self._lock:  # a setting made meanwhile waits for this shot and applies to the next
            new = seed is None
            if seed is None:
                seed = self.next_seed
            elif isinstance(seed, bool) or not isinstance(seed, int) or not self.first_seed <= seed < self.next_seed:
                given = (f"seeds {self.first_seed} to {self.next_seed - 1}" if self.next_seed > self.first_seed
                         else "no seed yet")
                raise InstrumentError(f"seed = {seed!r}: not one this rig has fired a shot at ({given})")
            record = self.shots(self.overrides, seed)
            self.fired += 1  # a refused shot is no shot: the next one takes its seed
            if new:
                self.next_seed += 1
            return Fired(record, seed, tuple(f"{k}={v}" for k, v in sorted(self.overrides.items())))
