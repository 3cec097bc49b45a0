"""A scene as the shot source of a virtual scope.

``SceneShots("ptfe52_magnetic", ["striker.velocity=0.9 m/s"])`` is the callable a virtual
scope is given (``instruments`` never imports the rig): called with ``(overrides, seed)``,
where ``overrides`` maps a dotted scene key to its value text with its unit (e.g.
``{"scope.channels.CH1.volts_per_div": "0.05 V"}``), it returns the ``ScopeRecord`` of
``Rig(scene with the base and these overrides).fire(seed)``: the very bits of
``rig shot SCENE --set KEY=VALUE ... --seed SEED``, because it reads the scene the way that
command does (``rig.experiment.scene.load`` of the "key=value" items).

The rigs built are kept per distinct set of overrides (a small LRU), so repeated shots cost
one fire each; a rig whose settings differ from a kept one only in ``scope.*`` keys takes
that rig's solved chain (the scope does not change what the chain does).

A scope whose trigger can never fire (NORMal, a rising level at or below the gauges' rest,
which ``rig shot`` refuses) gets the record of a shot that did not trigger, with the
refusal as its reason: the served scope waits for a trigger, as a real one armed in NORMal.

Every record the scope's settings describe is given (``record_solver``): where a record
lasts longer after its trigger than the scene's solve, the chain is solved for longer (past
its pulses it rings down and settles under the magnet and gravity, the striker bouncing off
and falling back as the model has it), and where the scope samples finer than the solver
records, the solver records at the scope's interval (its dense output: the cubic Hermite
interpolant of each step, never a held value). Those solver settings are items of the shot
like any other (``solver.duration=... s``, ``solver.sample_interval=... s``), so the record
is still that of ``rig shot`` with the same items. A refusal of the
rig (``RigError``) is raised as ``instruments.errors.InstrumentError`` with the same one
line, the form the instrument side puts in its error queue.
"""
from __future__ import annotations

import threading
from collections import OrderedDict
from collections.abc import Callable, Iterable, Mapping

from instruments.errors import InstrumentError
from instruments.records import ScopeRecord
from rig.errors import RigError, invalid
from rig.experiment.scene import load
from rig.experiment.shot import Rig, ShotRecord
from rig.lab.record_span import ESTIMATE_SEED, TRIGGER_MARGIN, after_trigger, record_bytes, record_solver
from rig.solver.estimate import LIMIT_BYTES, LIMIT_SECONDS

RIG_KEYS = ("striker.velocity", "magnet.force", "magnet.position")
"""The settings of the rig itself (not of the scope) that a lab client may change."""

HORIZONTAL_KEYS = ("scope.sample_interval", "scope.record_length", "scope.trigger.pre_trigger")
"""The scope's horizontal settings (scene keys): where its record lies in time."""

RECORD_KEYS = ("solver.duration", "solver.sample_interval")
"""The solver settings a record may need other than the scene's (record_solver)."""

SCOPE_PREFIX = "scope."  # settings of the scope only: the chain's solve does not depend on them


HISTORY_KEY = "chain.previous_shots"


def without_history(items) -> tuple:
    """The "key=value" items without chain.previous_shots: a rig built from them to check a
    setting or read its sizes solves no earlier shots (each would be a solve of the chain)."""
    return tuple(i for i in items if key_of(i) != HISTORY_KEY)


def key_of(item: str) -> str:
    """The key of a "key=value" item, as ``rig shot --set`` reads it."""
    return item.split("=", 1)[0].strip()


class SceneShots:
    """The shot source of one scene: ``(overrides, seed) -> ScopeRecord``.

    scene: a published scene's name or a scene file's path. base_overrides: the "key=value"
    items the scene is served with (``rig serve scope --set``), or a {key: value text}
    mapping; a key the call's overrides give again takes the call's value. on_shot: called
    with each shot's ``ShotRecord`` (what ``--out`` archives); ``last`` keeps the latest.
    cache: how many rigs (distinct override sets) are kept. allow_large: fire shots beyond
    the solver's size limits (rig/solver/estimate.py), as ``rig shot --allow-large``.
    A bad scene or base override raises RigError here, before any shot.
    """

    def __init__(self, scene, base_overrides: Iterable[str] | Mapping[str, str] = (), *,
                 on_shot: Callable[[ShotRecord], None] | None = None, cache: int = 8, allow_large: bool = False):
        if isinstance(base_overrides, Mapping):
            base_overrides = [f"{k}={v}" for k, v in base_overrides.items()]
        if isinstance(base_overrides, (str, bytes)):
            raise invalid("base_overrides", base_overrides, 'a list of "key=value" texts or a {key: value} mapping')
        if isinstance(cache, bool) or not isinstance(cache, int) or cache < 1:
            raise invalid("cache", cache, "a whole number of rigs >= 1")
        self.scene = scene
        self.base = tuple(base_overrides)
        self.loaded = load(scene, self.base)  # refused here, not at the first shot
        as_loaded = Rig(load(scene, without_history(self.base)))  # its record's timing: no history solved
        self.trigger_by = as_loaded.solver.duration - after_trigger(as_loaded)
        self.on_shot = on_shot
        self.allow_large = allow_large
        self.last: ShotRecord | None = None
        self._size = cache
        self._rigs: OrderedDict[tuple, Rig] = OrderedDict()
        self._estimates: OrderedDict[tuple, float | None] = OrderedDict()
        self._lock = threading.RLock()

    def items(self, overrides: Mapping[str, str]) -> tuple:
        """The "key=value" items a shot with ``overrides`` is fired with: the base items whose
        key the overrides do not give, then the overrides in key order."""
        if not isinstance(overrides, Mapping):
            raise InstrumentError(f"overrides = {overrides!r}: a mapping of scene keys to value texts")
        given = {str(k).strip(): str(v) for k, v in overrides.items()}
        kept = tuple(item for item in self.base if key_of(item) not in given)
        return kept + tuple(f"{k}={given[k]}" for k in sorted(given))

    def rig(self, overrides: Mapping[str, str] | None = None) -> Rig:
        """The rig of the scene with ``overrides`` (built once per distinct set; RigError)."""
        return self.rig_of(self.items(overrides or {}))

    def rig_of(self, items: tuple) -> Rig:
        """The rig of the scene with the "key=value" ``items`` (built once per distinct set;
        RigError)."""
        key = tuple(sorted(items))
        with self._lock:
            if key in self._rigs:
                self._rigs.move_to_end(key)
                return self._rigs[key]
            rig = self._built(items)
            solved = tuple(sorted(rig.scene.overrides))  # with the solver items its record needs
            twin = next((other for other in reversed(self._rigs.values())
                         if same_chain(solved, tuple(sorted(other.scene.overrides)))), None)
            if twin is not None:
                rig.use_solution(twin.solution())
            self._rigs[key] = rig
            if len(self._rigs) > self._size:
                self._rigs.popitem(last=False)
            return rig

    def _built(self, items: tuple) -> Rig:
        """A new rig of the scene with the "key=value" ``items`` and the solver items its
        record needs (``record_solver``), refused (RigError) where it could give no record or
        passes the size limits, before anything is solved."""
        rig = self._recording(items)
        rig.check_record(trigger=False)  # a trigger that never fires: the scope waits (__call__)
        rig.estimate().refuse_unless(self.allow_large, "this shot")
        return rig

    def _recording(self, items: tuple) -> Rig:
        """The rig of the scene with ``items`` and the solver items its record needs
        (record_solver), built before anything is solved (RigError where the scene refuses).
        A record the items' solve does not hold is solved until it ends: until its
        trigger, estimated by trigger_estimate and TRIGGER_MARGIN later (the scene's latest
        trigger where none is estimated), plus what it records after the trigger. The shot's
        items given again need nothing more (the same estimate: it reads the items without
        the solver's duration and interval)."""
        rig = Rig(load(self.scene, items))
        trigger_by = self.trigger_by
        if record_solver(rig, trigger_by):
            t = self.trigger_estimate(items)
            if t is not None:
                trigger_by = min(trigger_by, t * (1 + TRIGGER_MARGIN))
        extra = record_solver(rig, trigger_by)
        return Rig(load(self.scene, items + extra)) if extra else rig

    def trigger_estimate(self, items: tuple) -> float | None:
        """When (s after the impact) the scope with ``items``' settings triggers on the
        scene's own time base (its sample interval, record length and pre-trigger: a record
        that its solve holds, the solver's duration and interval the scene's) and its chain
        without earlier shots (history makes the pulse
        faster: the trigger earlier), at seed ESTIMATE_SEED; None where it does not trigger.
        Kept per set of items (a shot fired once; its chain solved once, in the rig cache)."""
        coarse = tuple(sorted(i for i in without_history(items) if key_of(i) not in HORIZONTAL_KEYS + RECORD_KEYS))
        with self._lock:
            if coarse not in self._estimates:
                self._estimates[coarse] = None  # a scene whose own time base is finer than its solver: no estimate
                try:
                    record = self.rig_of(coarse).fire(seed=ESTIMATE_SEED, truth=False).scope
                except RigError:
                    record = None  # refused on the scene's time base: the shot says why
                self._estimates[coarse] = record.trigger_time if record is not None and record.triggered else None
                if len(self._estimates) > self._size:
                    self._estimates.popitem(last=False)
            return self._estimates[coarse]

    def shot(self, overrides: Mapping[str, str], seed: int) -> ShotRecord:
        """The whole shot (scope record, settings, truth) with ``overrides`` and ``seed``;
        a refusal of the rig is an InstrumentError of one line."""
        with self._lock:
            try:
                shot = self.rig(overrides).fire(seed=seed)
            except RigError as exc:
                raise InstrumentError(str(exc)) from None
            self.last = shot
            if self.on_shot is not None:
                self.on_shot(shot)
            return shot

    def __call__(self, overrides: Mapping[str, str], seed: int) -> ScopeRecord:
        """The ShotSource: the scope record of ``shot(overrides, seed)``; where the scope's
        trigger can never fire (Rig.trigger_never_fires: NORMal, a rising level at or below
        the gauges' rest), the record of a shot that did not trigger, with that reason and
        nothing solved or fired (``rig shot`` refuses such a shot: the served scope, armed in
        NORMal, waits for a trigger that never comes)."""
        try:
            never = self.rig(overrides).trigger_never_fires()
        except RigError as exc:
            raise InstrumentError(str(exc)) from None
        if never is not None:
            return ScopeRecord({}, False, f"the trigger never fires: {never}")
        return self.shot(overrides, seed).scope

    def record_cost(self, overrides: Mapping[str, str]) -> str | None:
        """None when a shot with ``overrides`` is within the solver's size limits
        (rig/solver/estimate.py: its memory and seconds), else the one-line refusal naming
        its estimate: what the scope refuses at the setting command (other refusals of the
        rig wait for the shot, as they depend on more than the setting)."""
        try:  # the size of one shot: its history is solved once, apart
            rig = self._recording(without_history(self.items(overrides)))
        except RigError:
            return None  # refused at the shot, with its reason
        cost = rig.estimate()
        held = cost.bytes + record_bytes(rig)
        if self.allow_large or (held <= LIMIT_BYTES and cost.seconds <= LIMIT_SECONDS):
            return None
        s = rig.solver
        over = ([f"{LIMIT_BYTES / 1e9:g} GB"] if held > LIMIT_BYTES else []) + (
            [f"{LIMIT_SECONDS:g} s of solving"] if cost.seconds > LIMIT_SECONDS else [])
        return (f"this record needs about {held / 1e9:.3g} GB and {cost.seconds:.3g} s: the chain's "
                f"{s.duration * 1e3:.3g} ms solve (until the record ends) recorded every {s.sample_interval:.3g} s, "
                "the scope's sample "
                f"interval ({cost.samples:,} samples a channel), and the scope's {rig.scope.timebase.record_length:,} "
                f"points a channel; beyond the served scope's limit of {' and '.join(over)} (a coarser "
                "HORizontal:SCAle or a shorter record)")

    def validate(self, key: str, text: str) -> str | None:
        """None when ``key`` (one of RIG_KEYS) may be set to ``text`` (a quantity with its
        unit as in scene files, e.g. "0.9 m/s", "2.38 N"; a plain number is in SI), else the
        one-line refusal: the scene read with it and its parts built, as a shot would (the
        rig built is not kept: checking a value costs no shot's place in the cache)."""
        if key not in RIG_KEYS:
            return str(invalid("rig key", key, f"one of {', '.join(RIG_KEYS)}"))
        try:
            self._built(without_history(self.items({key: text})))  # the value's check: no earlier shot solved
        except (RigError, InstrumentError) as exc:
            return str(exc)
        return None


def same_chain(a: tuple, b: tuple) -> bool:
    """Whether two sorted item sets differ only in the scope's settings (the same solve)."""
    return {i for i in a if not key_of(i).startswith(SCOPE_PREFIX)} == {
        i for i in b if not key_of(i).startswith(SCOPE_PREFIX)}


def append_shot(archive, shot: ShotRecord) -> int:
    """Append a served shot to the archive at ``archive`` (a path) as ``rig shot --out``
    does; returns its shot number. An I/O failure is an OSError naming the path."""
    from instruments.archive import Archive
    from rig.experiment.entry import shot_entry

    return Archive(archive).append([shot_entry(shot)])[0]
