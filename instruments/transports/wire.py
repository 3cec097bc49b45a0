"""What keeps a served wire usable whatever its clients do: the limits of a listener
(``Limits``), the clock that says whether a connection is idle (``Clock``), one accepted
connection as its listener watches it (``Connection``), and the events a listener reports
to its owner (``ConnectionEvent``: a connection, its end and why, a refusal, a protocol
violation) so that a server above the transports can log them.

The limits, as ``TcpService`` applies them:

- at most ``max_clients`` connections at once; a peer address other than loopback holds at
  most ``per_address`` of them (half by default), so one remote host cannot take every slot
  (on loopback every local client is 127.0.0.1 or ::1: one address, so the share does not
  apply there; see eviction);
- eviction: when the slots (or an address's share) are taken, the connection that has
  completed no message for longest, if that is at least ``grace_s`` and it waits on nothing
  of the server's, is closed to make room for the newcomer (the address holding the most
  connections pays first); with none such, the newcomer is refused at once;
- idle: a connection that sends nothing for ``idle_timeout_s`` while no request of its is
  in progress (a query waiting on a shot is not idle) is closed (0: never);
- half-open: a connection that has not completed its protocol's opening (HiSLIP's
  Initialize and AsyncInitialize) within ``half_open_timeout_s`` is closed;
- stall: once a message has begun, a pause of ``stall_timeout_s`` in its bytes ends it (a
  raw-socket block is dropped and the connection goes on; in the framed protocols, which
  cannot find the next message, the connection is closed); a reply not taken for as long
  ends the connection too."""
from __future__ import annotations

import contextlib
import math
import socket
import threading
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from enum import Enum

from instruments.errors import InstrumentError
from instruments.transports.addresses import is_loopback

DETAIL_CHARS = 300
"""The longest detail an event's line keeps (what a client sent is cut, never kept whole)."""


@dataclass(frozen=True)
class Limits:
    """A listener's limits (see the module's docstring); each may be set, each is checked."""

    max_clients: int = 32
    per_address: int | None = None
    """Connections one address other than loopback may hold; None: half of max_clients."""
    idle_timeout_s: float = 300.0
    """No byte from the client, nothing of its pending, this long: closed. 0: never."""
    half_open_timeout_s: float = 10.0
    stall_timeout_s: float = 10.0
    grace_s: float = 10.0
    """How long a connection may complete no message before it can be evicted for a newcomer."""

    def __post_init__(self) -> None:
        if isinstance(self.max_clients, bool) or not isinstance(self.max_clients, int) \
                or not 1 <= self.max_clients <= 4096:
            raise InstrumentError(f"max_clients = {self.max_clients!r}: allowed a whole number from 1 to 4096")
        if self.per_address is not None and (isinstance(self.per_address, bool) or not isinstance(
                self.per_address, int) or not 1 <= self.per_address <= self.max_clients):
            raise InstrumentError(f"per_address = {self.per_address!r}: allowed a whole number from 1 to "
                                  f"max_clients ({self.max_clients}), or None (half of it)")
        for name in ("idle_timeout_s", "half_open_timeout_s", "stall_timeout_s", "grace_s"):
            value, zero_ok = getattr(self, name), name in ("idle_timeout_s", "grace_s")
            ok = isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value) \
                and (value >= 0 if zero_ok else value > 0) and value <= 86400
            if not ok:
                low = ("from 0 (never)" if name == "idle_timeout_s" else "from 0") if zero_ok else "> 0"
                raise InstrumentError(f"{name} = {value!r}: allowed seconds {low} to 86400")

    @property
    def share(self) -> int:
        """The connections one address other than loopback may hold."""
        return self.per_address if self.per_address is not None else max(1, self.max_clients // 2)

    def tick_s(self) -> float:
        """How often a listener looks at its connections' clocks."""
        spans = [t for t in (self.idle_timeout_s, self.half_open_timeout_s) if t > 0]
        return min(0.5, max(0.02, min(spans) / 5))


class EventKind(Enum):
    CONNECTED = "connected"
    DISCONNECTED = "disconnected"
    REFUSED = "refused"
    VIOLATION = "protocol violation"


@dataclass(frozen=True)
class ConnectionEvent:
    """Something a listener did or saw: ``service`` (which listener), ``peer`` (host:port),
    ``detail`` (why, in words; what the client sent appears escaped and cut)."""

    kind: EventKind
    service: str
    peer: str
    detail: str = ""

    def line(self) -> str:
        """One log line: printable, at most DETAIL_CHARS of detail."""
        detail = printable(self.detail)
        return f"{self.service} {self.peer} {self.kind.value}" + (f": {detail}" if detail else "")


EventSink = Callable[[ConnectionEvent], None]


def printable(text: str, most: int = DETAIL_CHARS) -> str:
    """``text`` on one line: control characters escaped, cut to ``most`` characters."""
    out = "".join(c if c.isprintable() else c.encode("unicode_escape").decode("ascii") for c in text)
    return out if len(out) <= most else out[:most - 3] + "..."


def quoted(message: bytes, most: int = 80) -> str:
    """What a client sent, for a log line: escaped, cut to ``most`` bytes."""
    text = repr(message[:most])[2:-1]
    return f"'{text}'" + ("..." if len(message) > most else "")


class Clock:
    """When a client was last heard, when it last completed a message, and how many of its
    requests are in progress; one per session (a HiSLIP session's two connections share one)."""

    def __init__(self) -> None:
        self._guard = threading.Lock()
        self.heard_at = self.done_at = time.monotonic()
        self.busy = 0

    def heard(self) -> None:
        """Bytes came from the client."""
        with self._guard:
            self.heard_at = time.monotonic()

    def done(self) -> None:
        """A message of the client's was taken whole (or its reply sent)."""
        with self._guard:
            self.heard_at = self.done_at = time.monotonic()

    @contextlib.contextmanager
    def working(self) -> Iterator[None]:
        """A request of the client's is in progress: the connection is neither idle nor evicted."""
        with self._guard:
            self.busy += 1
        try:
            yield
        finally:
            with self._guard:
                self.busy -= 1
                self.heard_at = self.done_at = time.monotonic()

    def pin(self, on: bool) -> None:
        """Hold the connection as busy (a portmapper registration lives as long as its connection)."""
        with self._guard:
            self.busy += 1 if on else -1

    def idle_s(self, now: float) -> float | None:
        """Seconds since the client was last heard; None while a request of its is in progress."""
        with self._guard:
            return None if self.busy else now - self.heard_at

    def quiet_s(self, now: float) -> float | None:
        """Seconds since its last complete message; None while a request of its is in progress."""
        with self._guard:
            return None if self.busy else now - self.done_at


class Connection:
    """One accepted connection: its socket, peer (``host:port``), address, clock, the
    opening message still awaited (``awaiting``; None once open) and, once its listener
    closed it, why (``reason``)."""

    def __init__(self, sock: socket.socket, peer: str, address: str, awaiting: str | None = None) -> None:
        self.sock, self.peer, self.address = sock, peer, address
        self.loopback = is_loopback(address)
        self.opened = time.monotonic()
        self.clock = Clock()
        self.awaiting = awaiting
        self.reason: str | None = None

    def close(self, reason: str) -> None:
        """End the connection for ``reason`` (the first reason given is the one logged)."""
        if self.reason is None:
            self.reason = reason
        with contextlib.suppress(OSError):
            self.sock.shutdown(socket.SHUT_RDWR)
