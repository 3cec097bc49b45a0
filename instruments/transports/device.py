"""What every transport serves: an IEEE 488.2 message-based instrument.

A transport takes complete program messages off the wire (the terminator or END already
removed) and hands each to its connection's ``Session``; what the session answers is the
response message the client reads next (ending in ``\\n``, as a Tektronix scope's replies do).
A query that streams (``Session.next_reply``) answers again and again until the client's next
message or device clear: VXI-11 hands out the next response on a read, a raw socket and
HiSLIP send it once the last one has left the connection (``stream.Pump``).
The instrument is one, shared by every connection and transport; a ``Session`` is one
client's view of it (its output queue). ``InstrumentLock`` is the lock VISA clients take
(HiSLIP's exclusive and shared locks, VXI-11's ``device_lock``), one per instrument, so a lock
taken over one transport holds on all."""
from __future__ import annotations

import threading
import time
from dataclasses import dataclass
from typing import Protocol


class Session(Protocol):
    """One client's connection to the instrument."""

    def handle(self, message: bytes) -> bytes:
        """Execute one complete program message; return the response (b"" when it held no
        query). May block while a query waits for the instrument (``*OPC?``)."""

    def device_clear(self) -> None:
        """IEEE 488.2 device clear: drop this session's pending input and output. It may come
        while ``handle`` runs in another thread (HiSLIP's clear arrives on its own channel):
        a query waiting there (``*OPC?``) should then end."""

    def next_reply(self, wait_s: float) -> bytes | None:
        """The next response of a query that answers more than once (a stream: the 4 Series'
        ``CURVEStream?`` sends a record per acquisition until another message or a device
        clear), asked for now that the transport can deliver it; b"" when it is not ready
        within ``wait_s`` (it comes on a later call); None when no stream is on. A transport
        asks for the next one only once the last has left it (a pulled read, or the
        connection's send queue empty), so nothing piles up where the client does not read."""

    def trigger(self) -> None:
        """The group execute trigger (``*TRG``) sent out of band (VXI-11 ``device_trigger``)."""

    def status_byte(self) -> int:
        """The status byte (``*STB?``), read out of band (serial poll)."""

    def overflow(self, size: int) -> None:
        """A program message of ``size`` bytes, over ``max_message_bytes``, was discarded by
        the transport unread; the instrument records the error in its queue."""

    def close(self) -> None:
        """The client is gone; forget what was queued for it."""


class MessageInstrument(Protocol):
    """An instrument a transport can serve."""

    max_message_bytes: int
    """The largest program message taken; a longer one is refused, not buffered."""

    lock: InstrumentLock

    def open_session(self, peer: str) -> Session:
        """A new client (``peer``: its address, for the log)."""


@dataclass(frozen=True)
class LockState:
    """Who holds the instrument's lock now (HiSLIP's AsyncLockInfo)."""

    exclusive: bool
    """True when one owner holds it exclusively."""
    holders: int
    """How many owners hold it, exclusively or shared."""


class InstrumentLock:
    """The instrument's lock: one exclusive holder, or shared holders that named the same
    lock string (HiSLIP, IVI-6.1 6.5), never both. Owners are opaque hashable keys (one per
    connection or link). ``acquire`` waits at most ``timeout_s``."""

    def __init__(self) -> None:
        self._cond = threading.Condition()
        self._exclusive: object | None = None
        self._shared: dict[object, str] = {}

    def acquire(self, owner: object, *, exclusive: bool = True, shared_name: str = "",
                timeout_s: float = 0.0) -> bool:
        """Take the lock for ``owner``; True when taken (or already held by it)."""
        deadline = time.monotonic() + max(timeout_s, 0.0)
        with self._cond:
            while True:
                if self._grantable(owner, exclusive, shared_name):
                    if exclusive:
                        self._exclusive = owner
                    else:
                        self._shared[owner] = shared_name
                    return True
                left = deadline - time.monotonic()
                if left <= 0:
                    return False
                self._cond.wait(left)

    def _grantable(self, owner: object, exclusive: bool, shared_name: str) -> bool:
        if self._exclusive not in (None, owner):
            return False
        if exclusive:
            return all(o == owner for o in self._shared)
        names = {n for o, n in self._shared.items() if o != owner}
        return not names or names == {shared_name}

    def release(self, owner: object) -> bool:
        """Drop what ``owner`` holds; True when it held something."""
        with self._cond:
            held = self._exclusive == owner or owner in self._shared
            if self._exclusive == owner:
                self._exclusive = None
            self._shared.pop(owner, None)
            self._cond.notify_all()
            return held

    def wait_unblocked(self, owner: object, timeout_s: float) -> bool:
        """Wait at most ``timeout_s`` until no other owner holds the lock exclusively; True
        when ``owner`` may go on (a transport holds a client's message while it is locked out)."""
        with self._cond:
            return self._cond.wait_for(lambda: self._exclusive in (None, owner), max(timeout_s, 0.0))

    def state(self) -> LockState:
        """Whether the lock is held exclusively, and by how many owners."""
        with self._cond:
            owners = set(self._shared) | ({self._exclusive} if self._exclusive is not None else set())
            return LockState(exclusive=self._exclusive is not None, holders=len(owners))

    def blocks(self, owner: object) -> bool:
        """True when another owner holds the lock exclusively (``owner`` may not write)."""
        with self._cond:
            return self._exclusive not in (None, owner)

    def holds(self, owner: object) -> bool:
        """True when ``owner`` holds the lock, exclusively or shared."""
        with self._cond:
            return self._exclusive == owner or owner in self._shared
