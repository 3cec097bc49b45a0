"""``rig serve scope``: a scene's virtual scope on the network, reached as VISA reaches a real one.

The scope (``instruments.virtual_scope.VirtualScope``) is served on a raw socket (always),
on HiSLIP and VXI-11 when asked, and its RIG: commands alone on a port of their own when
asked; every transport serves the one instrument. Before any port opens, one warm-up shot
is fired, so that no client waits for numba to compile: it is the scope's first
acquisition (seed N, with the settings the scope starts with), the record that ``CURVe?``
answers with before a client fires, as a real scope holds one from power-on. Shots are the
scene's (``rig.lab.shots.SceneShots``): the k-th one, the warm-up shot the first, is fired
at seed N + k - 1 and its record has the bits of ``rig shot SCENE --set ... --seed N+k-1``;
``--out`` archives each.

The address and every port are taken before the warm-up shot (a bad ``--host`` or a port in
use is refused at once, not after seconds of compiling); clients are let in after it. The
wire's limits are ``instruments.transports.wire.Limits`` (idle, half-open and stall timeouts,
a share of the connections per address, eviction of a quiet connection for a newcomer); an
address other than loopback is warned of in one line, and the resources printed are ones a
remote client can open. ``--log`` gets one line per listener, connection, disconnect (and
why), refusal, protocol violation, refused command (with the event it left in the queue),
shot, shot that did not trigger and refused shot. A second ``--vxi11`` server on loopback
whose portmapper maps another server's VXI-11 moves its VXI-11 channels to a loopback address
of its own (127.0.0.2, ...), with a portmapper there, so that both are found and neither
unregisters the other (rig/lab/serve_vxi11.py).
"""
from __future__ import annotations

import errno
import logging
import os
import socket
import threading
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TypeVar

from instruments.errors import InstrumentError
from instruments.records import ScopeRecord
from instruments.transports.addresses import is_loopback, is_wildcard, machine_addresses
from instruments.transports.device import MessageInstrument
from instruments.transports.hislip import HislipServer
from instruments.transports.portmap import PMAP_PORT
from instruments.transports.socket import SocketServer
from instruments.transports.vxi11 import Vxi11Server
from instruments.transports.wire import ConnectionEvent, EventKind, Limits, printable
from instruments.virtual_scope.instrument import VirtualScope
from rig.errors import invalid
from rig.experiment.shot import ShotRecord, fresh_seed
from rig.lab.serve_log import LoggedInstrument, Refusals, server_log
from rig.lab.serve_vxi11 import announce
from rig.lab.shots import SceneShots, append_shot


@dataclass(frozen=True)
class ServeSettings:
    """What ``rig serve scope`` was asked: the scene and its overrides ("key=value"), the
    address and ports (0: a free one; None: that transport off), the personality and an
    ``*IDN?`` to claim, how shots are fired, the first seed, the archive and log files, the
    wire's limits and the port a VXI-11 portmapper answers on (111, where clients ask)."""

    scene: str
    overrides: tuple = ()
    host: str = "127.0.0.1"
    port: int = 4000
    hislip: int | None = None
    vxi11: bool = False
    personality: str = "tds2000"
    idn: str | None = None
    fire: str = "on-arm"
    seed: int | None = None
    rig_port: int | None = None
    out: Path | None = None
    log: Path | None = None
    limits: Limits = field(default_factory=Limits)
    portmapper_port: int = PMAP_PORT


def fire_period(text: str) -> float | None:
    """The period (s) of ``--fire every=SECONDS``; None for on-arm and on-command."""
    if text in ("on-arm", "on-command"):
        return None
    head, _, value = text.partition("=")
    try:
        period = float(value) if head == "every" else float("nan")
    except ValueError:
        period = float("nan")
    if not 0.0 < period < 86400.0:
        raise invalid("--fire", text, "on-arm, on-command or every=SECONDS (0 < SECONDS < 86400)")
    return period


def rig_scene(shots: SceneShots) -> dict:
    """The scene's values of the settings the RIG: commands change, as text with units."""
    values = shots.loaded.values
    out = {}
    for key, unit in (("striker.velocity", "m/s"), ("magnet.force", "N"), ("magnet.position", "m")):
        table, name = key.split(".")
        value = values.get(table, {}).get(name)
        if value is not None:
            out[key] = f"{value:g} {unit}"
    return out


def front_panel_mode(shots: SceneShots) -> str | None:
    """The served scope's TRIGger:A:MODe at power-on and *RST: AUTO, the models' default,
    where the scene (with its --set items) does not give scope.trigger.mode; None (the
    scene's) where it does. The shots take it as an override like any setting."""
    return None if "mode" in shots.loaded.values.get("scope", {}).get("trigger", {}) else "auto"


def _port(name: str, port: int | None) -> None:
    if port is not None and not 0 <= port <= 65535:
        raise invalid(name, port, "a TCP port 0..65535 (0: a free one)")


_Server = TypeVar("_Server", SocketServer, HislipServer, Vxi11Server)


class ScopeServer:
    """The served scope and its transports; ``resources`` names them as VISA does."""

    def __init__(self, settings: ServeSettings, say: Callable[[str], None] = print) -> None:
        s = settings
        for name, port in (("--port", s.port), ("--hislip", s.hislip), ("--rig-port", s.rig_port)):
            _port(name, port)
        period = fire_period(s.fire)
        self.settings, self.say = s, say
        self.seed = fresh_seed() if s.seed is None else s.seed
        self.log = server_log(s.log)
        self.servers: list = []
        self._names: dict[int, str] = {}  # a server's id: what it serves, in words
        self.resources: list[str] = []
        self.stopped = threading.Event()
        self.shots = SceneShots(s.scene, s.overrides, on_shot=self._record)
        try:
            self.scope = VirtualScope(self.shots.rig().scope, self._fire, personality_name=s.personality,
                                      idn=s.idn, seed=self.seed, validate=self.shots.validate,
                                      record_cost=self.shots.record_cost,
                                      scene_name=str(s.scene), fire_period_s=period,
                                      on_command=s.fire == "on-command", rig_scene=rig_scene(self.shots),
                                      trigger_mode=front_panel_mode(self.shots))
        except InstrumentError as e:  # it names the setting (the personality, its record, --idn)
            raise invalid("rig serve scope", s.scene, str(e)) from None
        self.refusals = Refusals(self.scope, self.log)
        try:
            self._bind(s)  # the address and the ports, before the costly warm-up shot
            self._warn_if_exposed()
            say(f"warm-up shot of {s.scene} at seed {self.seed}, the scope's first acquisition "
                "(compiles what the shots need)")
            self.scope.acq.first_acquisition()  # InstrumentError: the rig refuses the scope's settings
            self._open(s)
        except BaseException:
            self.close()
            raise

    # ---- the transports ------------------------------------------------------------------

    def _bind(self, s: ServeSettings) -> None:
        """Make every server of the settings: their address and ports taken, nobody let in."""
        def logged(inner: MessageInstrument, transport: str) -> LoggedInstrument:
            return LoggedInstrument(inner, self.refusals, transport)

        lim, on = s.limits, self._on_event
        self._socket: SocketServer = self._bind_one(
            lambda: SocketServer(logged(self.scope, "raw socket"), s.host, s.port, limits=lim, on_event=on),
            "raw socket", "--port", s.port)
        self._hislip: HislipServer | None = None
        self._vxi11: Vxi11Server | None = None
        self._rig: SocketServer | None = None
        hislip, rig_port = s.hislip, s.rig_port
        if hislip is not None:
            self._hislip = self._bind_one(
                lambda: HislipServer(logged(self.scope, "HiSLIP"), s.host, hislip, limits=lim, on_event=on),
                "HiSLIP", "--hislip", hislip)
        if s.vxi11:
            self._vxi11 = self._bind_one(
                lambda: Vxi11Server(logged(self.scope, "VXI-11"), s.host, 0, limits=lim, on_event=on),
                "VXI-11 core channel", "--host", s.host)
        if rig_port is not None:
            self._rig = self._bind_one(
                lambda: SocketServer(logged(self.scope.rig_port(), "RIG: port"), s.host, rig_port, name="rig-port",
                                     limits=lim, on_event=on), "RIG: commands, raw socket", "--rig-port", rig_port)
        self.host = self._socket.host

    def _bind_one(self, make: Callable[[], _Server], what: str, option: str, port: int | str) -> _Server:
        """The server ``make()`` builds, its address and port taken; one it cannot take is
        one line naming the option."""
        try:
            server = make()
        except OSError as e:
            why = e.strerror or (os.strerror(e.errno) if e.errno else str(e))
            if isinstance(e, socket.gaierror) or e.errno in (errno.EADDRNOTAVAIL, errno.EAFNOSUPPORT):
                raise invalid("--host", self.settings.host, f"an address of this machine ({why}); "
                              "127.0.0.1 (loopback) unless clients elsewhere must reach it") from None
            raise invalid(option, port, f"a port free on {self.settings.host} ({why}), or 0 for any") from None
        self.servers.append(server)
        self._names[id(server)] = what
        return server

    def _warn_if_exposed(self) -> None:
        """One line (and the log's) when the instrument listens beyond this machine."""
        if is_loopback(self.host):
            return
        where = (f"every address of this machine ({self.host})" if is_wildcard(self.host) else self.host)
        line = (f"warning: the instrument is exposed unauthenticated on {where}: anyone who reaches it can "
                "command the scope and fire shots (--host 127.0.0.1 keeps it on this machine)")
        self.say(line)
        self.log.warning("%s", line)

    def _open(self, s: ServeSettings) -> None:
        """Let clients in, announce VXI-11, and name the resources."""
        for server in list(self.servers):
            server.start()
            self._listening(self._names[id(server)], server)
            if isinstance(server, Vxi11Server):
                self._tell(f"VXI-11 abort channel on {server.host} port {server.abort_port}")
                self._vxi11 = announce(server, s.portmapper_port, self._tell, self._vxi11_at)
                if self._vxi11 is not server:  # moved to a loopback address of its own
                    self.servers[self.servers.index(server)] = self._vxi11
                    self._names[id(self._vxi11)] = "VXI-11 core channel"
                    server.close()
        self.resources += [self._socket.resource_at(a) for a in self._addresses(self._socket.host)]
        if self._hislip is not None:
            self.resources += [self._hislip.resource_at(a) for a in self._addresses(self._hislip.host)]
        if self._vxi11 is not None:
            vx = self._vxi11
            for a in self._addresses(vx.host):  # and by its core port, no portmapper asked
                self.resources += list(dict.fromkeys([vx.resource_at(a), vx.resource_at(a, by_port=True)]))
        if self._rig is not None:
            self.resources += [f"{self._rig.resource_at(a)} (RIG: commands)" for a in self._addresses(self._rig.host)]

    def _listening(self, what: str, server: SocketServer | HislipServer | Vxi11Server) -> None:
        self._tell(f"{what} on {server.host} port {server.port}")

    def _tell(self, line: str) -> None:
        """Say ``line`` and log it."""
        self.say(line)
        self.log.info("%s", line)

    def _vxi11_at(self, address: str) -> Vxi11Server:
        """The scope's VXI-11 server on ``address``, started."""
        return Vxi11Server(LoggedInstrument(self.scope, self.refusals, "VXI-11"), address, 0,
                           limits=self.settings.limits, on_event=self._on_event).start()

    @staticmethod
    def _addresses(host: str) -> list[str]:
        """The addresses a client opens a server listening on ``host`` at: this machine's
        own for a wildcard (0.0.0.0, ::), which no remote client can open."""
        return machine_addresses(host) if is_wildcard(host) else [host]

    # ---- what the log says ---------------------------------------------------------------

    def _on_event(self, event: ConnectionEvent) -> None:
        """A transport's event: one line of the log."""
        quiet = event.kind in (EventKind.CONNECTED, EventKind.DISCONNECTED)
        self.log.log(logging.INFO if quiet else logging.WARNING, "%s", event.line())

    def _fire(self, overrides: Mapping[str, str], seed: int) -> ScopeRecord:
        """The scope's shot source: the scene's shot, a refusal logged (then raised, for the
        scope to queue), a shot that did not trigger logged (the scope, armed, waits)."""
        settings = " ".join(f"{k}={v}" for k, v in overrides.items()) or "the scene as loaded"
        try:
            record = self.shots(overrides, seed)
        except Exception as e:
            self.refusals.shot_refused(str(e))
            self.log.warning("refused shot at seed %d (%s): %s", seed, printable(settings), printable(str(e)))
            raise
        if not record.waveforms:
            self.log.info("shot at seed %d (%s) did not trigger: %s", seed, printable(settings),
                          printable(record.reason or ""))
        return record

    def _record(self, shot: ShotRecord) -> None:
        """A served shot finished: log it, archive it (``--out``)."""
        self.log.info("shot: seed %d, %s", shot.seed, " ".join(shot.overrides) or "the scene as loaded")
        if self.settings.out is not None:
            try:
                append_shot(self.settings.out, shot)
            except OSError as e:
                self.log.error("shot at seed %d not archived: %s", shot.seed, e)
                raise InstrumentError(f"--out = {self.settings.out}: {e.strerror or e}") from None

    def wait(self) -> None:
        """Serve until ``stop()`` (a signal handler calls it)."""
        while not self.stopped.wait(0.5):
            pass

    def stop(self) -> None:
        self.stopped.set()

    def close(self) -> None:
        """Close every transport (their clients see the connection end), the scope's
        acquisition and the log."""
        for server in reversed(self.servers):
            server.close()
        self.servers.clear()
        self.scope.close()
        for handler in list(self.log.handlers):
            handler.close()
            self.log.removeHandler(handler)


def serve(settings: ServeSettings, say: Callable[[str], None] = print, as_json: bool = False) -> None:
    """Serve until SIGINT/SIGTERM. The line naming the resources is one line with the word
    "listening" (JSON with ``as_json``: {"listening": [...], "seed": N, "scene": ...})."""
    import json
    import signal

    server = ScopeServer(settings, say)
    try:
        previous = {sig: signal.signal(sig, lambda *_: server.stop()) for sig in (signal.SIGINT, signal.SIGTERM)}
        say(f"serving {settings.scene} as a {settings.personality}, first seed {server.seed}")
        say(json.dumps({"listening": server.resources, "seed": server.seed, "scene": str(settings.scene),
                        "personality": settings.personality}) if as_json else
            "listening: " + "  ".join(server.resources))
        server.wait()
        for sig, handler in previous.items():
            signal.signal(sig, handler)
    finally:
        server.close()
    say("stopped")
