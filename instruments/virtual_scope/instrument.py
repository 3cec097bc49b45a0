"""The emulated Tektronix scope as a message-based instrument (transports/device.py).

One instrument state (settings, acquisition, status, reply forms) is shared by every
session and transport; one program message is executed at a time under the instrument's
condition, which a query waiting for a shot (``*OPC?``, ``*WAI``) releases while it waits,
so other sessions are answered during a shot. The scope starts from the scene's scope
(``instruments.devices.oscilloscope.Oscilloscope``), its record length and s/div snapped to the
personality's (those count as overrides); ``*RST`` returns there. ``rig_port()`` serves the
RIG: commands alone, on the same state, for a separate port. No command reads or writes a
file (FILESystem and SAVe:WAVEform are undefined headers; the TDS2000's SAVe:SETUp and
RECAll:SETUp take set-up locations, a file path is -221). Replies start with HEADer OFF (what
TDS2000-family scripts and qcodes' TPS2012 driver read without asking) and VERBose ON;
``*RST`` leaves both as they are."""
from __future__ import annotations

import math
import threading
from collections.abc import Callable
from functools import partial

from ..devices.oscilloscope import Oscilloscope
from ..errors import InstrumentError
from ..scpi.engine import Engine, ReplyForm
from ..scpi.status import OPC, ScpiError, StatusModel
from ..scpi.tree import CommandTree
from ..transports.device import InstrumentLock
from . import (
    clock,
    commands,
    common,
    configuration,
    display,
    horizontal,
    manual_settings,
    measurements,
    rig_commands,
    setup,
    stream,
    tds_commands,
    waveform_commands,
)
from .acquisition import Acquisition, ShotSource
from .manual import in_manual
from .measurements import default_slots
from .personalities import personality, snap_to_steps
from .settings import acquired, overrides, scene_settings, scope_of
from .stream import CurveStream
from .transfer import DataSelection

Validate = Callable[[str, str], "str | None"]
"""(scene key, value text) -> None when the rig takes it, else its one-line refusal."""
RecordCost = Callable[[dict], "str | None"]
"""(overrides of a shot) -> None when its record is within the shot source's limits, else
the one-line refusal naming its cost."""
HORIZONTAL = ("scope.sample_interval", "scope.record_length", "scope.trigger.pre_trigger")
"""The settings that decide how long and how fine a record is."""


class VirtualScope:
    """The emulated scope. scope: the scene's; shot_source: (overrides, seed) -> ScopeRecord;
    personality: tds2000 | mdo3000 | mso4 (``idn`` overrides its *IDN?); seed: the first
    shot's; validate: checks RIG: values; on_shot(Shot): called after each shot; bounds:
    max_message_bytes (program message), max_reply_bytes (one message's replies),
    max_record_length (points; None: the model's longest record); opc_timeout_s: the longest *OPC? wait; fire_period_s /
    on_command: how an armed scope gets shots (acquisition.py): every so many seconds, or
    only from TRIGger FORCe, *TRG and RIG:FIRE; neither: at once; on_shot is called for the
    shots that give a record. rig_scene: the scene's
    values of the RIG: settings as text ({"striker.velocity": "0.89 m/s", ...}), what their
    queries answer until a client sets them. record_cost: asked when a horizontal setting
    changes (HORIZONTAL); a record past the shot source's limits is refused there (-221).
    trigger_mode: TRIGger:A:MODe at power-on and after *RST, "auto" or "normal" (None: the
    scene's scope.trigger.mode); the shots take it as the scene key scope.trigger.mode."""

    def __init__(self, scope: Oscilloscope, shot_source: ShotSource, *, personality_name: str = "tds2000",
                 idn: str | None = None, seed: int = 0, validate: Validate | None = None, on_shot=None,
                 scene_name: str = "", max_message_bytes: int = 1 << 20, max_reply_bytes: int = 64 << 20,
                 max_record_length: int | None = None, opc_timeout_s: float = 600.0,
                 fire_period_s: float | None = None, on_command: bool = False,
                 rig_scene: dict | None = None, record_cost: RecordCost | None = None,
                 trigger_mode: str | None = None) -> None:
        if isinstance(seed, bool) or not isinstance(seed, int) or not 0 <= seed < 2 ** 63:
            raise InstrumentError(f"seed = {seed!r}: a whole number from 0 to 2^63 - 1")
        self.scene, self.scene_name = scope, scene_name
        self.personality = personality(personality_name, idn)
        self.validate = validate or (lambda key, text: None)
        self.record_cost = record_cost or (lambda overrides: None)
        self.rig_scene = dict(rig_scene or {})
        self.max_message_bytes, self.max_reply_bytes = max_message_bytes, max_reply_bytes
        self.max_record_length = max_record_length or self.personality.record_lengths[-1]
        self.opc_timeout_s = opc_timeout_s
        self.lock = InstrumentLock()
        self.cond = threading.Condition()
        self.status = StatusModel()
        self.stream: CurveStream | None = None  # the curve stream on (CURVEStream?), one at a time
        self.form = ReplyForm(header=False)
        self.initial = self._personality_settings(scene_settings(scope))
        if trigger_mode is not None:
            self.initial["scope.trigger.mode"] = trigger_mode
        scope_of(self.initial, acquired(scope, set()), scope)  # InstrumentError: the scene suits no such model
        self.acq = Acquisition(self.cond, shot_source, self.overrides_locked, self.status.post, self._set_opc,
                               seed, on_shot, period_s=fire_period_s, on_command=on_command)
        with self.cond:
            self.reset()
        tree, rig_tree = CommandTree(truncation=True), CommandTree(truncation=True)  # DATA:SOUR as on a Tek
        for t in (tree, rig_tree):
            common.register(t, self)
            rig_commands.register(t, self)
        commands.register(tree, self)
        clock.register(tree)
        horizontal.register(tree, self)
        waveform_commands.register(tree, self)
        stream.register(tree, self)
        measurements.register(tree, self)
        setup.register(tree, self)
        configuration.register(tree, self)
        tds_commands.register(tree, self)  # the TDS2000's other names for the commands above
        display.register(tree, self)  # after the modelled display commands: the manual's others, kept
        manual_settings.register(tree, self)  # last: its group queries answer the settings registered above
        in_model_manual = partial(in_manual, self.personality.name)
        self.engine = Engine(tree, self.status, self.form, in_model_manual)
        self.rig_engine = Engine(rig_tree, self.status, self.form, in_model_manual)

    def _personality_settings(self, s: dict) -> dict:
        """The scene's settings on this model: its record length nearest the scene's (within
        max_record_length), the s/div snapped to its steps, the sample interval they give."""
        lengths = [n for n in self.personality.record_lengths if n <= self.max_record_length]
        if not lengths:
            raise InstrumentError(f"max_record_length = {self.max_record_length}: the {self.personality.name} "
                                  f"takes at least {self.personality.record_lengths[0]} points")
        n = min(lengths, key=lambda x: abs(math.log(x / s["scope.record_length"])))
        s_div = snap_to_steps(s["scope.sample_interval"] * s["scope.record_length"] / 10,
                              self.personality.time_steps)
        return {**s, "scope.record_length": n, "scope.sample_interval": s_div * 10 / n}

    # --- state, all under self.cond ------------------------------------------------
    def reset(self) -> None:
        """*RST: the scene's settings as loaded (the personality's snapping kept), the
        default DATa and acquisition (running, idle: acquisition.py); the seed sequence goes on."""
        self.settings = dict(self.initial)
        self.shown = set(self.scene.channels)
        self.rig_values: dict = {}  # RIG: settings, scene key -> value text
        self.data = DataSelection(stop=self.initial["scope.record_length"])
        self.horizontal_mode = "AUTO"  # HORizontal:MODe (4 Series), and in MANual what a new rate moves
        self.manual_configure = "HORIZontalscale"
        self.measurements = default_slots(next(iter(self.scene.channels)), self.personality.name)
        self.numavg = self.scene.averages if self.scene.mode == "average" else 16
        self.trigger_levels: dict = {}  # TRIGger:A:LEVel:CH<x>: each channel's own level (V), set by a client
        self.display_waveform = True  # DISplay:WAVEform: the screen only, the records are the same
        self.b_trigger = {"source": "CH1", "slope": "RISe", "level": 0.0}  # TRIGger:B:EDGE, kept; B is off
        self.acq.reset()

    def channels(self) -> tuple:
        return acquired(self.scene, self.shown)

    def change(self, updates: dict, shown: set | None = None, code: int = -221) -> None:
        """Apply settings (scene key -> SI value) and the channels shown, or raise ``code``
        (-221 settings conflict, -222 data out of range) with the oscilloscope's refusal and
        change nothing."""
        settings, shown = {**self.settings, **updates}, self.shown if shown is None else shown
        try:
            if not shown:
                raise InstrumentError("display at least one channel")
            scope_of(settings, acquired(self.scene, shown), self.scene)
        except InstrumentError as e:
            raise ScpiError(code, str(e)) from None
        if any(settings[k] != self.settings[k] for k in HORIZONTAL):
            channels = acquired(self.scene, shown)
            refusal = self.record_cost({**overrides(self.scene, settings, channels), **self.rig_values})
            if refusal is not None:
                raise ScpiError(-221, refusal)
        self.settings, self.shown = settings, set(shown)

    def overrides_locked(self, forced: bool = False) -> dict:
        """overrides() holding the condition; ``forced``: a forced trigger's shot, taken in
        AUTO (scope.trigger.mode auto: acquisition.py)."""
        settings = {**self.settings, "scope.trigger.mode": "auto"} if forced else self.settings
        return {**overrides(self.scene, settings, self.channels()), **self.rig_values}

    def overrides(self) -> dict:
        """The settings that differ from the scene as loaded, {scene key: value text}: what
        the next shot is fired with."""
        with self.cond:
            return self.overrides_locked()

    def _set_opc(self) -> None:
        self.status.set_bits(OPC)

    def wait_idle(self, session) -> None:
        """Wait (the lock released) until no shot is pending; -410 when the session was
        cleared meanwhile, -200 on timeout."""
        mark = session.clears
        ok = self.cond.wait_for(lambda: not self.acq.awaiting or session.clears != mark or self.acq.closed,
                                timeout=self.opc_timeout_s)
        if session.clears != mark:
            raise ScpiError(-410, "device clear during *OPC?/*WAI")
        if not ok:
            raise ScpiError(-200, f"no record after {self.opc_timeout_s:g} s")

    # --- MessageInstrument -------------------------------------------------------------
    def open_session(self, peer: str) -> ScopeSession:
        return ScopeSession(self, self.engine, peer)

    def rig_port(self) -> RigPort:
        """The RIG: commands (and the common ones) on the same state, for another port."""
        return RigPort(self)

    def close(self) -> None:
        self.acq.close()


class RigPort:
    """A MessageInstrument serving the rig's commands of a VirtualScope."""

    def __init__(self, scope: VirtualScope) -> None:
        self.scope, self.lock, self.max_message_bytes = scope, scope.lock, scope.max_message_bytes

    def open_session(self, peer: str) -> ScopeSession:
        return ScopeSession(self.scope, self.scope.rig_engine, peer)


class ScopeSession:
    """One client: runs its messages on the shared engine, one at a time. A message, a
    device clear or the client's going ends its curve stream (stream.py)."""

    def __init__(self, scope: VirtualScope, engine: Engine, peer: str) -> None:
        self.scope, self.engine, self.peer = scope, engine, peer
        self.clears = 0
        self.stream: CurveStream | None = None

    def _end_stream(self) -> None:
        """Out of streaming mode (holding the scope's condition)."""
        if self.stream is not None:
            self.stream.end()
            self.stream = None

    def next_reply(self, wait_s: float) -> bytes | None:
        """The next block of this client's curve stream (CurveStream.next_block): b"" when
        not in within ``wait_s``, None when no stream is on."""
        with self.scope.cond:
            stream = self.stream
            if stream is None:
                return None
            block = stream.next_block(wait_s)
            if stream.ended and self.stream is stream:
                self.stream = None
            return block

    def handle(self, message: bytes) -> bytes:
        scope = self.scope
        with scope.cond:
            self._end_stream()  # the manual: another command or query ends the streaming mode
            if len(message) > scope.max_message_bytes:
                scope.status.post(-363, f"a message of {len(message)} bytes (at most {scope.max_message_bytes})")
                return b""
            reply = self.engine.execute(message, self)
            scope.acq.poke()  # on-arm in run mode: the rig strikes again when a client talks to the scope
            if len(reply) > scope.max_reply_bytes:
                scope.status.post(-350, f"a reply of {len(reply)} bytes exceeds the output queue's "
                                        f"{scope.max_reply_bytes}; nothing sent")
                return b""
            return reply

    def device_clear(self) -> None:
        with self.scope.cond:
            self.clears += 1
            self._end_stream()
            self.scope.cond.notify_all()

    def trigger(self) -> None:
        with self.scope.cond:
            self.scope.acq.force()

    def status_byte(self) -> int:
        """The status byte without MAV: the transport holds the reply and adds MAV."""
        with self.scope.cond:
            return self.scope.status.status_byte(False)

    def overflow(self, size: int) -> None:
        with self.scope.cond:
            self.scope.status.post(-363, f"a message of {size} bytes (at most {self.scope.max_message_bytes})")

    def close(self) -> None:
        self.device_clear()
