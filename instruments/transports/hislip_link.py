"""One HiSLIP session (IVI-6.1): its two connections, the instrument session behind them and
what the synchronous and asynchronous channels share (the reply's delivery, the device clear
in progress, the lock it holds)."""
from __future__ import annotations

import contextlib
import socket
import threading
from collections.abc import Callable

from instruments.transports.device import InstrumentLock, Session
from instruments.transports.hislip_codec import HEADER, Kind, message
from instruments.transports.stream import Pump
from instruments.transports.tcp import send_all
from instruments.transports.wire import Clock, Connection

DEFAULT_CLIENT_MAX = 1 << 20
"""The client's maximum message size until it says another (VISA's default, bytes)."""
WAIT_SLICE_S = 0.2
"""How long a wait for the lock runs before it looks whether the session ended (s)."""


class Link:
    """One HiSLIP session: its synchronous and asynchronous connections, the instrument
    session behind them, and what the two channels share."""

    def __init__(self, session_id: int, sync: socket.socket, session: Session, lock: InstrumentLock,
                 max_message: int, *, watch: Connection | None = None,
                 report: Callable[[str], None] = lambda text: None) -> None:
        self.id = session_id
        self.sync = sync
        self.asynchronous: socket.socket | None = None
        self.session = session
        self.lock = lock
        self.max_message = max_message
        """The largest message taken, in bytes (HiSLIP message and program message alike)."""
        self.client_max = DEFAULT_CLIENT_MAX
        self.undelivered = False
        """A reply was sent and the client has not said it took all of it (MAV)."""
        self.held: bool | None = None
        """What this session holds of the lock: True exclusive, False shared, None nothing."""
        self.clearing = threading.Event()
        self.closed = threading.Event()
        """Set when the session is ending: it is granted nothing more."""
        self._ended = False
        self._ending = threading.Lock()
        self._sync_out = threading.Lock()
        self._async_out = threading.Lock()
        self.watched: list[Connection] = [watch] if watch is not None else []
        """The connections as their listener watches them (idle, half-open)."""
        self.clock: Clock = watch.clock if watch is not None else Clock()
        """The session's clock: either channel's traffic keeps both alive."""
        self.report = report
        """Tells the server's owner of a protocol violation (in words)."""
        self.pump: Pump | None = None
        """Sends a streamed reply (CURVEStream?) while it lasts; the next message stops it."""

    @property
    def half_open(self) -> bool:
        """Initialized on its synchronous channel, its asynchronous one not paired yet."""
        return self.asynchronous is None

    def attach_async(self, conn: socket.socket, watch: Connection | None = None) -> bool:
        """Pair the asynchronous connection; False when one is paired already. Both
        connections are then open and share the session's clock."""
        if self.asynchronous is not None:
            return False
        self.asynchronous = conn
        if watch is not None:
            watch.clock = self.clock
            self.watched.append(watch)
        for c in self.watched:
            c.awaiting = None
        return True

    def send_sync(self, kind: int, control: int = 0, parameter: int = 0, payload: bytes = b"") -> None:
        with self._sync_out:
            send_all(self.sync, message(kind, control, parameter, payload))

    def send_async(self, kind: int, control: int = 0, parameter: int = 0, payload: bytes = b"") -> None:
        assert self.asynchronous is not None, "the channels are served once both are paired"
        with self._async_out:
            send_all(self.asynchronous, message(kind, control, parameter, payload))

    def send_reply(self, reply: bytes, message_id: int) -> None:
        """The instrument's reply to message ``message_id``, in parts the client takes; a
        device clear stops it between parts."""
        part = max(self.client_max - HEADER.size, 1)
        self.undelivered = True
        with self._sync_out:
            for start in range(0, len(reply), part):
                if self.clearing.is_set():
                    return
                last = start + part >= len(reply)
                send_all(self.sync, message(Kind.DATA_END if last else Kind.DATA, 0, message_id,
                                            reply[start:start + part]))

    def stop_pump(self) -> None:
        """No more of a streamed reply: a new message came, the device was cleared, the end."""
        pump, self.pump = self.pump, None
        if pump is not None:
            pump.stop()

    def wait_unlocked(self) -> bool:
        """Hold a message while another client holds the lock exclusively; False when the
        session ends or is cleared first."""
        while not self.lock.wait_unblocked(self, WAIT_SLICE_S):
            if self.closed.is_set() or self.clearing.is_set():
                return False
        return True

    def close(self, reason: str = "the other connection of its HiSLIP session ended", *,
              by: Connection | None = None) -> None:
        """End the session: its lock released, both connections shut (once); ``reason`` is
        what the log says of each connection but ``by`` (the one whose end ends the session)
        that its listener had not closed for another reason."""
        for c in self.watched:
            if c is not by and c.reason is None:
                c.reason = reason
        with self._ending:
            if self._ended:
                return
            self._ended = True
        self.closed.set()
        self.lock.release(self)
        self.stop_pump()
        self.session.close()
        for conn in (self.sync, self.asynchronous):
            if conn is not None:
                with contextlib.suppress(OSError):
                    conn.shutdown(socket.SHUT_RDWR)
