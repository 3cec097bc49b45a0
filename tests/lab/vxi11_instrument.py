"""A small honest message-based instrument for the transport tests (no SCPI engine, no rig):
it answers what it is asked and keeps count of what was done to it, so a test can see each
transport operation arrive.

Commands (one per message, case-insensitive):
  *IDN?          -> "TEST,ECHO-VXI11,0,1"
  ECHO? text     -> text
  DATA? n        -> an IEEE 488.2 definite-length block of n bytes (byte k = k mod 251)
  SLEEP s        -> takes s seconds (a slow command), no response
  SYST:ERR?      -> the oldest queued error, '0,"No error"' when none
  TRG? / CLR?    -> how many triggers / device clears this instrument has had
  anything else without "?" is taken silently; a query it does not know queues an error.
The status byte: bit 2 (EAV) while the error queue holds an error; MAV is the transport's."""
from __future__ import annotations

import threading
import time

from instruments.transports.device import InstrumentLock

IDN = b"TEST,ECHO-VXI11,0,1"
EAV = 0x04


def block(n: int) -> bytes:
    """The DATA? payload: n bytes, byte k = k mod 251 (a prime: no alignment hides a slip)."""
    payload = bytes(k % 251 for k in range(251)) * (n // 251 + 1)
    return payload[:n]


class EchoInstrument:
    """MessageInstrument: one state shared by every session (triggers, clears, errors)."""

    def __init__(self, max_message_bytes: int = 1 << 20) -> None:
        self.max_message_bytes = max_message_bytes
        self.lock = InstrumentLock()
        self._guard = threading.Lock()
        self.triggers = 0
        self.clears = 0
        self.errors: list[str] = []
        self.sessions_open = 0
        self.messages: list[bytes] = []

    def open_session(self, peer: str) -> EchoSession:
        with self._guard:
            self.sessions_open += 1
        return EchoSession(self)


class EchoSession:
    def __init__(self, instrument: EchoInstrument) -> None:
        self.inst = instrument
        self.closed = False

    def handle(self, message: bytes) -> bytes:
        inst = self.inst
        with inst._guard:
            inst.messages.append(message)
        text = message.decode("ascii", "replace").strip()
        head, _, arg = text.partition(" ")
        head = head.upper()
        if head == "*IDN?":
            return IDN + b"\n"
        if head == "ECHO?":
            return arg.encode() + b"\n"
        if head == "DATA?":
            n = int(arg)
            return b"#%d%d" % (len(str(n)), n) + block(n) + b"\n"
        if head == "SLEEP":
            time.sleep(float(arg))
            return b""
        if head == "SYST:ERR?":
            with inst._guard:
                return (inst.errors.pop(0) if inst.errors else '0,"No error"').encode() + b"\n"
        if head == "TRG?":
            return b"%d\n" % inst.triggers
        if head == "CLR?":
            return b"%d\n" % inst.clears
        if head.endswith("?"):
            with inst._guard:
                inst.errors.append(f'-113,"Undefined header; {head}"')
        return b""

    def next_reply(self, wait_s: float) -> bytes | None:
        return None  # no query of this instrument streams

    def device_clear(self) -> None:
        with self.inst._guard:
            self.inst.clears += 1

    def trigger(self) -> None:
        with self.inst._guard:
            self.inst.triggers += 1

    def status_byte(self) -> int:
        with self.inst._guard:
            return EAV if self.inst.errors else 0

    def overflow(self, size: int) -> None:
        with self.inst._guard:
            self.inst.errors.append(f'-223,"Too much data; {size} bytes"')

    def close(self) -> None:
        self.closed = True
        with self.inst._guard:
            self.inst.sessions_open -= 1
