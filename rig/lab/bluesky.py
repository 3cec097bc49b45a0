"""ophyd-async devices of the rig, for bluesky plans (needs the ``bluesky`` extra).

``VirtualScope`` reads the scope: one sub-device per displayed channel (``scope.ch1``, ...)
whose ``waveform`` (volts, one float per sample) is read in every event and whose time axis
(sample interval, time of the first sample from the trigger, points) and vertical scale are
its configuration; the scope's ``seed`` (the shot's) is read too. ``trigger()`` fires one
shot and completes when its record is in. ``Magnet`` (``set(force)``, newtons) and
``Striker`` (``set(velocity)``, m/s) are movables whose readback is a read signal, so each
event holds the value its shot was fired with. The devices share one ``ShotBackend``
(rig/lab/backend.py); every backend call runs in a worker thread, never on the event loop.

    bench = InProcessBench("ptfe52_magnetic", seed=1)
    scope, magnet = VirtualScope(bench, name="scope"), Magnet(bench, name="magnet")
"""
from __future__ import annotations

import asyncio

import numpy as np
from bluesky.protocols import Movable
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


class VirtualScope(StandardReadable):
    """The rig's oscilloscope: ``trigger()`` fires the next shot (seed N + k - 1 for the
    k-th) and waits for its record; a shot that did not trigger fails the trigger with the
    scope's reason."""

    def __init__(self, backend: ShotBackend, name: str = ""):
        self.backend = backend
        self.last: Fired | None = None
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

    @AsyncStatus.wrap
    async def trigger(self) -> None:
        fired = await asyncio.to_thread(self.backend.fire)
        record = fired.record
        if not record.triggered:
            raise InstrumentError(f"the scope did not trigger (seed {fired.seed}): {record.reason}")
        missing = [ch for ch in self.backend.channels if ch not in record.waveforms]
        if missing:  # an event must not carry an earlier shot's waveform
            raise InstrumentError(f"channels = {', '.join(missing)}: not in the record of seed {fired.seed} "
                                  f"(it holds {', '.join(record.waveforms)})")
        for ch, waveform in record.waveforms.items():
            self.channel(ch).show(waveform)
        self._show_seed(fired.seed)
        self.last = fired


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
