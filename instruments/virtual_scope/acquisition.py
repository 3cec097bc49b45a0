"""The emulated scope's acquisition system: run/stop, single sequence, fired and forced shots, seeds.

Shots run in one worker thread, outside the instrument's message lock, so every session
keeps being answered while the rig computes a shot. ``ACQuire:STOPAfter SEQuence`` with
``ACQuire:STATE ON`` arms the scope for one record; ``RUNSTop`` for records back to back
until ``ACQuire:STATE OFF``. How an armed scope gets its shots is the rig's (``rig serve
scope --fire``): at once (on-arm: one impact each time the scope is armed, and in run mode
one more at the first client message after each record: the rig strikes again when a program
next talks to the scope, not back to back while nobody asks, so that a program that leaves
the scope running, as one that restores the state it found does, leaves no rig firing and
archiving records that nobody reads until the server stops), at the ticks of a period
(every=SECONDS, as a rig that drops its striker periodically), or only from the fire
commands (on-command: the armed scope waits for the impact). ``RIG:FIRE`` fires a shot now
(an impact, in the trigger's mode); ``TRIGger FORCe``, ``*TRG`` and the transports' device
trigger force one (programmer manuals, TRIGger: "FORCe creates a trigger event"): the shot
is taken as TRIGger:A:MODe AUTO takes it, with the shot item scope.trigger.mode=auto, so a
shot whose input never crosses the level gives the untriggered record AUTO gives
(oscilloscope.Trigger). On a stopped scope a forced trigger is ignored, no shot and no seed
("If TRIGger:STATE is set to READy, the acquisition will complete. Otherwise, this command
will be ignored").

Power-on and ``*RST`` leave the scope running (the manuals' default setup: ACQuire:STATE ON,
ACQuire:STOPAfter RUNSTop; ACQuire:STATE: "When state is set to ON or RUN, a new acquisition
will be started"), as a scope on a bench whose rig is at rest: it waits for an impact. The
rig strikes on its own (on-arm, every=SECONDS) only once a client has armed the scope
(ACQuire:STATE ON|RUN, or a curve stream); until then no seed is taken but by a client's
``RIG:FIRE`` or forced trigger, so that the k-th shot fired still uses seed N + k - 1 however
long a client takes to configure the scope. Such a record, in run mode, leaves the scope
running and waiting again; in a single sequence (STOPAfter SEQuence set meanwhile) it ends
it. The idle running scope has nothing pending (``BUSY?`` 0, ``*OPC?`` at once); the
untriggered records a real scope in AUTO would take between impacts are not made.

In NORMal (the manuals, TRIGger:A:MODe: "NORMal waits for a valid trigger event") a shot
that does not trigger makes no record and the armed scope stays armed, the last record kept
("If no trigger occurs, the last waveform record acquired remains on the display", 4 Series
Quick Start): ``ACQuire:STATE?`` 1, ``TRIGger:STATE?`` READY, and in a single sequence
``BUSY?`` 1 and ``*OPC?`` waiting, until a shot that triggers (the next tick; ``RIG:FIRE``),
a forced trigger, ``ACQuire:STATE OFF``, ``*RST`` or, for the waiting query, a device clear.
On-arm, its impact spent, it waits for these (no impact is fired again until it is armed
again). Such a shot takes its seed (the striker fell) and is no acquisition (ACQuire:NUMACq);
a ``RIG:FIRE`` on a stopped scope that does not trigger queues an execution error saying so.

A shot takes the settings as they are when it starts (a change during a shot applies to the
next) and the next seed: the k-th shot fired uses seed N + k - 1 (a refused shot uses none).
``*OPC?``/``*WAI`` wait while a single sequence or a fired shot is pending. While a curve
stream is on (``stream``: CURVEStream?) the stream paces the acquisition: a shot is due only
when the stream asks for its next record (``want``), at once, at the next tick or on a fire
command as above, so that no record is made that no client asked for."""
from __future__ import annotations

import math
import threading
import time
from collections import deque
from collections.abc import Callable, Mapping
from dataclasses import dataclass

from ..errors import InstrumentError
from ..records import ScopeRecord

ShotSource = Callable[[Mapping[str, str], int], ScopeRecord]
"""(overrides: scene key -> value text with its unit, seed) -> the shot's ScopeRecord."""


@dataclass(frozen=True)
class Shot:
    """A finished shot: the overrides and seed it was fired with, and its record."""

    overrides: Mapping[str, str]
    seed: int
    record: ScopeRecord


class Acquisition:
    """The acquisition state (guarded by ``cond``, the instrument's condition) and its worker.

    snapshot(forced) -> the overrides of the next shot (called holding ``cond``; ``forced``:
    a forced trigger's, taken in AUTO); post(code, detail) queues an event (holding
    ``cond``); done_opc() sets ESR's OPC bit; on_shot(Shot) is called after each finished
    shot with a record, outside the lock."""

    def __init__(self, cond: threading.Condition, source: ShotSource, snapshot, post, done_opc,
                 seed: int = 0, on_shot=None, *, period_s: float | None = None, on_command: bool = False) -> None:
        if period_s is not None and not 0 < period_s < math.inf:
            raise InstrumentError(f"fire_period_s = {period_s!r}: a period > 0 s, or None")
        self.cond, self.source, self.snapshot, self.post = cond, source, snapshot, post
        self.done_opc, self.on_shot = done_opc, on_shot
        self.period_s, self.on_command = period_s, on_command
        self.epoch = self.next_tick = time.monotonic()  # the ticks: epoch + k period
        self.next_seed = int(seed)
        self.stop_after = "RUNSTop"
        self.running = False
        self.idle = False  # running as *RST leaves it: the rig strikes only once a client arms it
        self.pending: deque[bool] = deque()  # shots fired by command, not yet begun: forced (True) or impacts
        self.spent = False  # on-arm: the armed scope's impact came and did not trigger
        self.resting = False  # on-arm, run mode: a record is in; the next impact waits for a client's message
        self.busy = False
        self.commanded = False  # the shot under way was fired by a command (not by arming)
        self.opc_armed = False
        self.count = 0
        self.finished = 0  # shots ended with a record or refused: a stream waits for the next
        self.streaming = False  # a curve stream paces the shots (CURVEStream?)
        self.wanted = False  # the stream asked for its next record
        self.last: Shot | None = None
        self.failure: str | None = None  # why the last shot failed (its record is gone), None after a good one
        self.closed = False
        self.thread = threading.Thread(target=self._work, name="scope-shots", daemon=True)
        self.thread.start()

    @property
    def awaiting(self) -> bool:
        """A shot that *OPC? waits for is pending or running, or a single sequence waits for
        its trigger (BUSY? 1)."""
        return bool(self.pending or (self.running and not self.idle and self.stop_after == "SEQuence")
                    or (self.busy and not self.running))

    @property
    def acquiring(self) -> bool:
        """ACQuire:STATE? 1: running, streaming, or a shot on its way."""
        return bool(self.running or self.streaming or self.busy or self.pending)

    def reset(self) -> None:
        """Power-on and *RST: run mode (RUNSTop), running, idle (waiting for an impact: the
        rig does not strike until a client arms the scope), no fired shot pending."""
        self.stop_after = "RUNSTop"
        self.pending.clear()
        self.running, self.idle, self.spent = True, True, False
        self.cond.notify_all()

    def run(self, on: bool) -> None:
        """ACQuire:STATE: armed (a new acquisition, "When state is set to ON or RUN, a new
        acquisition will be started", also on a running scope: the first tick is the next one,
        and on-arm an impact) or stopped."""
        if on:
            self._next_tick()
            self.spent = self.resting = False
        self.running, self.idle = on, False
        self.cond.notify_all()

    def _next_tick(self) -> None:
        """The first tick from now, where shots come every period."""
        if self.period_s is not None:
            now = time.monotonic()
            self.next_tick = self.epoch + self.period_s * (math.floor((now - self.epoch) / self.period_s) + 1)

    def stream(self, on: bool) -> None:
        """A curve stream begins (its shots due only when it asks, ``want``) or ends (a
        record asked for and not begun is not made)."""
        if on and not self.streaming:
            self._next_tick()
            self.spent = False
        self.streaming, self.wanted = on, False
        self.cond.notify_all()

    def want(self) -> None:
        """The stream asks for the next record (on-arm: an impact for it)."""
        self.wanted, self.spent = True, False
        self.cond.notify_all()

    def poke(self) -> None:
        """A client's message was handled: on-arm in run mode, a scope whose record is in
        gets its next impact now (``resting``)."""
        if self.resting:
            self.resting = False
            self.cond.notify_all()

    def fire(self, forced: bool = False) -> None:
        """A shot now: an impact (RIG:FIRE), or ``forced``, a forced trigger (TRIGger FORCe,
        *TRG): taken as AUTO takes it."""
        self.pending.append(forced)
        self.cond.notify_all()

    def force(self) -> None:
        """TRIGger FORCe, *TRG, the transports' device trigger: a forced shot now on an
        acquiring scope (running, or a curve stream on); ignored on a stopped one: "If
        TRIGger:STATE is set to READy, the acquisition will complete. Otherwise, this command
        will be ignored" (programmer manuals, TRIGger)."""
        if self.running or self.streaming:
            self.fire(forced=True)

    def opc(self) -> None:
        """*OPC: OPC set now, or when the pending shot is in."""
        if self.awaiting:
            self.opc_armed = True
        else:
            self.done_opc()

    def close(self) -> None:
        with self.cond:
            self.closed = True
            self.running = False
            self.pending.clear()
            self.cond.notify_all()

    def _wait_for_a_shot(self) -> str | None:
        """Wait (holding ``cond``) until a shot is due: "forced", "fired" (an impact by
        command) or "armed", or None once closed. Due: a fired or forced shot, or while armed
        (ACQuire:STATE ON by a client, not idle; while a stream is on, only when it asked for
        a record) at once
        unless its impact is spent, or at the next tick of the period, or never (on_command:
        only fired shots, an armed scope waits for them). The stream's record stays asked for
        until a shot gives one."""
        while not self.closed:
            if self.pending:
                return "forced" if self.pending.popleft() else "fired"
            armed = (self.wanted if self.streaming else self.running and not self.idle) and not self.on_command
            due = armed and self.period_s is None and not self.spent and not self.resting
            now = time.monotonic()
            if armed and self.period_s is not None and now >= self.next_tick:
                self.next_tick += self.period_s * (1 + math.floor((now - self.next_tick) / self.period_s))
                due = True
            if due:
                return "armed"
            self.cond.wait(self.next_tick - now if armed and self.period_s is not None else None)
        return None

    def first_acquisition(self) -> Shot:
        """Fire one shot now in the caller's thread, before any client is served: the record
        a scope holds from power-on, so that ``CURVe?`` answers before a client fires. It is
        the first shot (seed N, counted, ``on_shot`` called); InstrumentError with the
        rig's reason when it fails (one that does not trigger is kept, as later ones)."""
        with self.cond:
            overrides, seed = self._take_seed("fired")
        shot, error = self._shoot(overrides, seed)
        if shot is None:
            raise InstrumentError(f"the first shot, at seed {seed}: {error}")
        return shot

    def _take_seed(self, kind: str) -> tuple:
        """(overrides, seed) of the shot of ``kind`` (_wait_for_a_shot's) that starts now
        (holding ``cond``)."""
        overrides, seed = dict(self.snapshot(kind == "forced")), self.next_seed
        self.next_seed += 1
        self.busy, self.commanded = True, kind != "armed"
        return overrides, seed

    def _work(self) -> None:
        while True:
            with self.cond:
                kind = self._wait_for_a_shot()
                if kind is None:
                    return
                overrides, seed = self._take_seed(kind)
            self._shoot(overrides, seed)

    def _shoot(self, overrides: dict, seed: int) -> tuple:
        """Fire the shot, keep it as the last record, tell ``on_shot``: (Shot, None), or
        (None, the reason) when it failed."""
        record, error = self._fire(overrides, seed)
        shot = None if record is None else Shot(overrides, seed, record)
        with self.cond:
            self._finish(shot, seed, error)
        if shot is not None and shot.record.waveforms and self.on_shot is not None:
            try:
                self.on_shot(shot)
            except Exception as e:  # noqa: BLE001 - the instrument keeps serving; the client is told
                with self.cond:
                    self.post(-200, f"the shot of seed {seed} was not kept: {type(e).__name__}: {e}")
        return shot, error

    def _fire(self, overrides: dict, seed: int):
        try:
            return self.source(overrides, seed), None
        except InstrumentError as e:
            return None, str(e)
        except Exception as e:  # noqa: BLE001 - a failing shot must not stop the instrument
            return None, f"the shot failed: {type(e).__name__}: {e}"

    def _finish(self, shot: Shot | None, seed: int, error: str | None) -> None:
        self.busy = False
        if shot is not None and not shot.record.waveforms:  # NORMal, no trigger: no record
            if self.running or self.streaming:
                self.spent = True  # armed still, the last record kept: it waits for a trigger
            elif self.commanded:  # fired on a stopped scope (RIG:FIRE, the first acquisition): said
                self.post(-200, f"the shot of seed {seed} did not trigger: {shot.record.reason}; "
                                "no record, the last one kept")
        else:
            self._ended(shot, seed, error)
        if self.opc_armed and not self.awaiting:
            self.opc_armed = False
            self.done_opc()
        self.cond.notify_all()

    def _ended(self, shot: Shot | None, seed: int, error: str | None) -> None:
        """A shot ended with a record, or refused (``shot`` None, ``error`` why): the
        sequence done, the stream's record in."""
        self.finished, self.wanted, self.spent = self.finished + 1, False, False
        if shot is None:  # no stale record may pass for this shot's: the last one is dropped
            self.post(-200, error)
            self.last, self.failure = None, error
            if self.next_seed == seed + 1:
                self.next_seed = seed  # a refused shot takes no seed
            self.running = False
        else:
            self.last, self.failure, self.count = shot, None, self.count + 1
        if self.stop_after == "SEQuence":
            self.running = False
        self.resting = self.running and not self.streaming
