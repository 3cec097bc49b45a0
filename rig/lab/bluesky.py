"""ophyd-async devices of the rig, for bluesky plans (needs the ``bluesky`` extra).

``VirtualScope`` reads the scope: one sub-device per displayed channel (``scope.ch1``, ...)
whose ``waveform`` (volts, one float per sample) is read in every event and whose time axis
(sample interval, time of the first sample from the trigger, points) and vertical scale are
its configuration; the scope's ``seed`` (the shot's) is read too. ``trigger()`` fires one
shot and completes when its record is in. ``Magnet`` (``set(force)``, newtons) and
``Striker`` (``set(velocity)``, m/s) are movables whose readback is a read signal, so each
event holds the value its shot was fired with. The devices share one ``ShotBackend``
(rig/lab/backend.py); every backend call runs in a worker thread, never on the event loop.

Pause and resume: the scope is bluesky's ``Pausable``. A plan with a checkpoint before each
shot (bluesky's ``count``, ``scan``, ``list_scan``, ``grid_scan``; the rig's plans.py) paused
at a checkpoint (one Ctrl-C, a deferred pause) has no shot in flight, and resumes with the
next seed. Paused at once (Ctrl-C twice, ``RunEngine.request_pause()``) while a shot is in
flight, the RunEngine drops the event being bundled, rewinds to the checkpoint before that
shot and, on resume, triggers the scope again: that trigger fires the same shot again at its
own seed (``ShotBackend.fire(seed)``), so the events keep the seeds N, N+1, ... with none
skipped or used twice (``VirtualScope`` names the two instants of a pause where that fails).

    bench = InProcessBench("ptfe52_magnetic", seed=1)
    scope, magnet = VirtualScope(bench, name="scope"), Magnet(bench, name="magnet")
"""
from __future__ import annotations

import asyncio

import numpy as np
from bluesky.protocols import Movable, Pausable, Reading
from ophyd_async.core import Array1D, AsyncStatus, StandardReadable, StandardReadableFormat, soft_signal_r_and_setter

from instruments.errors import InstrumentError
from rig.lab.backend import Fired, ShotBackend


class ScopeChannel(StandardReadable):
    """One displayed channel of the scope: its last record in volts and its time axis."""

    def __init__(self, name: str = ""):
        with self.add_children_as_readables():
            self.waveform, self._show_waveform = soft_signal_r_and_setter(Array1D[np.float64], units="V")
        with self.add_children_as_readables(StandardReadableFormat.CONFIG_SIGNAL):
            self.sample_interval, self._show_interval = soft_signal_r_and_setter(float, units="s")
            self.first_sample_time, self._show_first = soft_signal_r_and_setter(float, units="s")
            self.points, self._show_points = soft_signal_r_and_setter(int)
            self.volts_per_div, self._show_scale = soft_signal_r_and_setter(float, units="V")
        super().__init__(name=name)

    def show(self, waveform) -> None:
        """Take a channel's record (an instruments Waveform) as the last one."""
        p = waveform.preamble
        self._show_waveform(waveform.volts().astype(np.float64))
        self._show_interval(float(p.x_increment))
        self._show_first(float(p.x_zero))
        self._show_points(int(p.points))
        self._show_scale(float(p.extra.get("volts_per_div", np.nan)))


class VirtualScope(StandardReadable, Pausable):
    """The rig's oscilloscope: ``trigger()`` fires the next shot (seed N + k - 1 for the
    k-th) and waits for its record; a shot that did not trigger fails the trigger with the
    scope's reason.

    A shot is in flight from its trigger until the scope is read (the reading goes into the
    shot's event). ``pause()``, which the RunEngine calls as it pauses, keeps the shot in
    flight, if any: the RunEngine rewinds to the checkpoint before it and triggers again on
    resume, and that next trigger waits for the kept shot, then fires it again at its own
    seed (a shot the rig refused fired nothing: its seed is the next one's). A shot already
    read is delivered, and the next trigger fires the next seed.

    The scope's reading is the mark it sees, not the event's save, so two instants of an
    immediate pause stay as bluesky has them. After the scope's reading and before the save
    (one loop turn of the RunEngine where the scope is read last, as in plans.py; in bluesky's
    own plans, which read the detectors first, also while the motors are read), the RunEngine
    redoes the event with the next seed, and the read shot's seed goes unused. Between the save
    and the next checkpoint (one loop turn), it emits the event again (bluesky's replay: the
    same seq_num, with the next seed). A pause at a checkpoint (one Ctrl-C) falls in neither.
    """

    def __init__(self, backend: ShotBackend, name: str = ""):
        self.backend = backend
        self.last: Fired | None = None
        self._in_flight: asyncio.Task[Fired] | None = None  # the last trigger's shot, until it is read
        self._redo: asyncio.Task[Fired] | None = None  # the shot a pause caught in flight
        with self.add_children_as_readables():
            self.seed, self._show_seed = soft_signal_r_and_setter(int)
            for ch in backend.channels:
                setattr(self, ch.lower(), ScopeChannel())
        super().__init__(name=name)

    def channel(self, name: str) -> ScopeChannel:
        """The sub-device of a channel ("CH1")."""
        if name not in self.backend.channels:
            raise InstrumentError(f"channel = {name!r}: displayed are {', '.join(self.backend.channels)}")
        return getattr(self, name.lower())

    def trigger(self) -> AsyncStatus:
        """Fire a shot (the next seed, or again the one a pause caught) and show its record."""
        redo, self._redo = self._redo, None
        shot = asyncio.ensure_future(self._fire(redo))
        self._in_flight = shot
        return AsyncStatus(self._show(shot))

    async def _fire(self, redo: asyncio.Task[Fired] | None) -> Fired:
        seed = None
        if redo is not None:
            try:
                seed = (await redo).seed  # the caught shot is in first: the rig fires one shot at a time
            except InstrumentError:
                seed = None  # refused, so never fired: the sequence has not given its seed
        return await asyncio.to_thread(self.backend.fire, seed)

    async def _show(self, shot: asyncio.Task[Fired]) -> None:
        fired = await shot
        record = fired.record
        if not record.waveforms:  # NORMal and no trigger (in AUTO the scope takes an untriggered record)
            raise InstrumentError(f"the scope did not trigger (seed {fired.seed}): {record.reason}")
        missing = [ch for ch in self.backend.channels if ch not in record.waveforms]
        if missing:  # an event must not carry an earlier shot's waveform
            raise InstrumentError(f"channels = {', '.join(missing)}: not in the record of seed {fired.seed} "
                                  f"(it holds {', '.join(record.waveforms)})")
        for ch, waveform in record.waveforms.items():
            self.channel(ch).show(waveform)
        self._show_seed(fired.seed)
        self.last = fired

    async def read(self) -> dict[str, Reading]:
        """The last shot's waveforms and seed; the shot is delivered (no longer in flight)."""
        reading = await super().read()
        self._in_flight = self._redo = None
        return reading

    def pause(self) -> None:
        """The RunEngine pauses: a shot in flight is fired again, at its seed, by the next trigger."""
        if self._in_flight is not None:
            self._redo = self._in_flight

    def resume(self) -> None:
        """The RunEngine resumes: nothing to do (the rewound plan triggers again)."""


class RigSetting(StandardReadable, Movable[float]):
    """A scene key as a movable: ``set(value)`` (SI units) changes it for the next shots;
    its readback, read back from the backend (the value the next shot is fired with), is
    read in every event."""

    key = ""
    unit = ""
    readback_name = ""

    def __init__(self, backend: ShotBackend, name: str = ""):
        self.backend = backend

        async def read_back() -> float:
            return await asyncio.to_thread(backend.value, self.key)

        with self.add_children_as_readables(StandardReadableFormat.HINTED_UNCACHED_SIGNAL):
            readback, _ = soft_signal_r_and_setter(float, units=self.unit, getter=read_back)
            setattr(self, self.readback_name, readback)
        super().__init__(name=name)

    @AsyncStatus.wrap
    async def set(self, value: float) -> None:
        await asyncio.to_thread(self.backend.set, self.key, f"{float(value)!r} {self.unit}")


class Magnet(RigSetting):
    """The ring magnet's pull on the top bead: ``set(force)`` in N; readback ``force``."""

    key, unit, readback_name = "magnet.force", "N", "force"


class Striker(RigSetting):
    """The striker: ``set(velocity)`` in m/s; readback ``velocity``."""

    key, unit, readback_name = "striker.velocity", "m/s", "velocity"
