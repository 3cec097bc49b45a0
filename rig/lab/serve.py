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
"""
from __future__ import annotations

import errno
import logging
import os
import threading
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from instruments.errors import InstrumentError
from instruments.transports.hislip import HislipServer
from instruments.transports.socket import SocketServer
from instruments.transports.vxi11 import Vxi11Server
from instruments.virtual_scope.instrument import VirtualScope
from rig.errors import invalid
from rig.experiment.shot import ShotRecord, fresh_seed
from rig.lab.shots import SceneShots, append_shot


@dataclass(frozen=True)
class ServeSettings:
    """What ``rig serve scope`` was asked: the scene and its overrides ("key=value"), the
    address and ports (0: a free one; None: that transport off), the personality and an
    ``*IDN?`` to claim, how shots are fired, the first seed, the archive and log files."""

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


def _port(name: str, port: int | None) -> None:
    if port is not None and not 0 <= port <= 65535:
        raise invalid(name, port, "a TCP port 0..65535 (0: a free one)")


class ScopeServer:
    """The served scope and its transports; ``resources`` names them as VISA does."""

    def __init__(self, settings: ServeSettings, say: Callable[[str], None] = print) -> None:
        s = settings
        for name, port in (("--port", s.port), ("--hislip", s.hislip), ("--rig-port", s.rig_port)):
            _port(name, port)
        period = fire_period(s.fire)
        self.settings, self.say = s, say
        self.seed = fresh_seed() if s.seed is None else s.seed
        self.log = _logger(s.log)
        self.shots = SceneShots(s.scene, s.overrides, on_shot=self._record)
        try:
            self.scope = VirtualScope(self.shots.rig().scope, self.shots, personality_name=s.personality,
                                      idn=s.idn, seed=self.seed, validate=self.shots.validate,
                                      record_cost=self.shots.record_cost,
                                      scene_name=str(s.scene), fire_period_s=period,
                                      on_command=s.fire == "on-command", rig_scene=rig_scene(self.shots))
        except InstrumentError as e:  # it names the setting (the personality, its record, --idn)
            raise invalid("rig serve scope", s.scene, str(e)) from None
        say(f"warm-up shot of {s.scene} at seed {self.seed}, the scope's first acquisition "
            "(compiles what the shots need)")
        self.servers: list = []
        self.resources: list[str] = []
        try:
            self.scope.acq.first_acquisition()  # InstrumentError: the rig refuses the scope's settings
            self._open(s)
        except BaseException:
            self.close()
            raise
        self.stopped = threading.Event()

    def _open(self, s: ServeSettings) -> None:
        sock = self._start(lambda: SocketServer(self.scope, s.host, s.port), "raw socket", "--port", s.port)
        self.resources.append(sock.resource)
        if s.hislip is not None:
            hs = self._start(lambda: HislipServer(self.scope, s.host, s.hislip), "HiSLIP", "--hislip", s.hislip)
            self.resources.append(hs.resource)
        if s.vxi11:
            vx = self._start(lambda: Vxi11Server(self.scope, s.host, 0), "VXI-11 core channel", "--host", s.host)
            self.say(f"VXI-11 abort channel on {vx.host} port {vx.abort_port}")
            try:
                self.say(f"VXI-11: {vx.announce()}")
            except InstrumentError as e:  # no portmapper: clients name the core port
                self.say(f"VXI-11: {e}")
            self.resources.append(vx.resource)
            if vx.resource != f"TCPIP::{s.host},{vx.port}::INSTR":  # the core port named: no portmapper asked
                self.resources.append(f"TCPIP::{s.host},{vx.port}::INSTR")
        if s.rig_port is not None:
            rp = self._start(lambda: SocketServer(self.scope.rig_port(), s.host, s.rig_port),
                             "RIG: commands, raw socket", "--rig-port", s.rig_port)
            self.resources.append(f"{rp.resource} (RIG: commands)")

    def _start(self, make, what: str, option: str, port: int | str):
        """Start the server ``make()`` builds; a port it cannot take is one line naming the
        option."""
        try:
            server = make()
        except OSError as e:
            why = os.strerror(e.errno) if e.errno else str(e)
            if e.errno == errno.EADDRNOTAVAIL:  # no interface of this machine has that address
                raise invalid("--host", self.settings.host, f"an address of this machine ({why}); "
                              "127.0.0.1 (loopback) unless clients elsewhere must reach it") from None
            raise invalid(option, port, f"a port free on {self.settings.host} ({why}), or 0 for any") from None
        self.servers.append(server.start())
        self.say(f"{what} on {server.host} port {server.port}")
        self.log.info("%s on %s port %d", what, server.host, server.port)
        return server

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


def _logger(path: Path | None) -> logging.Logger:
    """The server's log (``--log FILE``: appended, one line per event); silent without one."""
    log = logging.getLogger(f"rig.lab.serve.{id(path)}")
    log.propagate = False
    log.setLevel(logging.INFO)
    if path is not None:
        try:
            handler = logging.FileHandler(path, encoding="utf-8")
        except OSError as e:
            raise invalid("--log", str(path), f"a file this process can write ({e.strerror})") from None
        handler.setFormatter(logging.Formatter("%(asctime)s %(levelname)s %(message)s"))
        log.addHandler(handler)
    return log


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
