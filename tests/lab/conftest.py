"""What the lab tests serve: a small message-based instrument (``EchoInstrument``) for the
transports, the emulated scope on a synthetic shot source (``make_scope``), and the lock of
port 111 (``port111``); pyvisa with the pyvisa-py backend is the client, as in a lab script.

The instrument answers ``*IDN?``; ``ECHO? <bytes>`` with the bytes; ``DATA? <n>`` with an
IEEE 488.2 definite-length block of n bytes (byte k is k mod 251); ``WAIT? <s>`` after s
seconds, or at once when a device clear comes, with ``DONE``; ``SYST:ERR?`` with the oldest
error (``-363`` input buffer overrun for a message dropped for its size, ``-113`` undefined
header); ``COUNT? TRG|CLEAR`` with how many triggers and device clears it took. Its status
byte has bit 2 (error queue not empty). One message is handled at a time, as on a real
instrument."""
from __future__ import annotations

import fcntl
import tempfile
import threading
import time
import warnings
from pathlib import Path

import pytest

from instruments.transports.device import InstrumentLock
from instruments.virtual_scope.instrument import VirtualScope
from lab.lab_scope import PulseSource, scene_scope, velocity_only

IDN = b"RIG,TRANSPORT-TEST,0,1.0"
EAV = 0x04


def pattern(n: int) -> bytes:
    """The ``DATA? n`` payload: byte k is k mod 251 (every block differs from a shifted copy)."""
    return bytes(k % 251 for k in range(251)) * (n // 251) + bytes(range(n % 251))


def block(data: bytes) -> bytes:
    """``data`` as an IEEE 488.2 definite-length block."""
    return b"#%d%d" % (len(str(len(data))), len(data)) + data


class EchoInstrument:
    """An honest ``MessageInstrument`` for transport tests (see the module's docstring)."""

    IDN = IDN
    pattern = staticmethod(pattern)

    def __init__(self, max_message_bytes: int = 256 * 1024) -> None:
        self.max_message_bytes = max_message_bytes
        self.lock = InstrumentLock()
        self.busy = threading.Lock()
        self.triggers = 0
        self.clears = 0
        self.open = 0

    def open_session(self, peer: str) -> EchoSession:
        with self.busy:
            self.open += 1
        return EchoSession(self)


class EchoSession:
    def __init__(self, instrument: EchoInstrument) -> None:
        self.instrument = instrument
        self.errors: list[bytes] = []
        self.cleared = threading.Event()

    def handle(self, message: bytes) -> bytes:
        with self.instrument.busy:
            return self._execute(message)

    def _execute(self, message: bytes) -> bytes:
        header, _, argument = message.partition(b" ")
        header = header.upper()
        if header == b"*IDN?":
            return IDN + b"\n"
        if header == b"ECHO?":
            return argument + b"\n"
        if header == b"DATA?":
            return block(pattern(int(argument))) + b"\n"
        if header == b"WAIT?":  # a wait a device clear ends, as *OPC? on a scope
            self.cleared.clear()
            self.cleared.wait(float(argument))
            return b"DONE\n"
        if header == b"SYST:ERR?":
            return (self.errors.pop(0) if self.errors else b'0,"No error"') + b"\n"
        if header == b"COUNT?":
            count = {b"TRG": self.instrument.triggers, b"CLEAR": self.instrument.clears}[argument.upper()]
            return b"%d\n" % count
        self.errors.append(b'-113,"Undefined header; %s"' % header[:40])
        return b""

    def next_reply(self, wait_s: float) -> bytes | None:
        return None  # no query of this instrument streams

    def device_clear(self) -> None:
        self.instrument.clears += 1
        self.cleared.set()

    def trigger(self) -> None:
        self.instrument.triggers += 1

    def status_byte(self) -> int:
        return EAV if self.errors else 0

    def overflow(self, size: int) -> None:
        self.errors.append(b'-363,"Input buffer overrun; message of %d bytes dropped"' % size)

    def close(self) -> None:
        with self.instrument.busy:
            self.instrument.open -= 1


@pytest.fixture
def instrument():
    return EchoInstrument()


@pytest.fixture(scope="module")
def rm():
    """pyvisa's resource manager on the pyvisa-py backend, one per test module."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # pyvisa-py warns that no GPIB library is installed
        import pyvisa

        manager = pyvisa.ResourceManager("@py")
    yield manager
    manager.close()


def _eventually(condition, timeout_s: float = 3.0) -> bool:
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if condition():
            return True
        time.sleep(0.02)
    return condition()


@pytest.fixture
def eventually():
    """``eventually(condition, timeout_s=3)``: True as soon as ``condition()`` is, False after
    the timeout (for what a server does in its own threads)."""
    return _eventually


@pytest.fixture
def make_scope():
    """make_scope(personality="tds2000", **kw) -> (VirtualScope, session, PulseSource): an
    emulated scope on a synthetic shot source (lab_scope.py)."""
    made = []

    def make(personality="tds2000", scene=None, **kw):
        scene = scene or scene_scope(10_000 if personality != "tds2000" else 2500)
        source = PulseSource(scene)
        scope = VirtualScope(scene, source, personality_name=personality, validate=velocity_only,
                             scene_name="synthetic", **kw)
        made.append(scope)
        return scope, scope.open_session("test"), source

    yield make
    for scope in made:
        scope.close()


@pytest.fixture(scope="module")
def port111():
    """Port 111 (the portmapper VXI-11 clients ask) is one per machine: a module that serves
    on it holds this lock, so that two test processes (pytest -n, --dist loadfile) never serve
    there at once."""
    with open(Path(tempfile.gettempdir()) / "sonic-rig-tests-port111.lock", "w") as f:
        fcntl.flock(f, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(f, fcntl.LOCK_UN)
