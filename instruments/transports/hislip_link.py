"""One HiSLIP session (IVI-6.1): its two connections, the instrument session behind them and
what the synchronous and asynchronous channels share (the reply's delivery, the device clear
in progress, the lock it holds)."""
from __future__ import annotations

import contextlib
import socket
import threading

from instruments.transports.device import InstrumentLock, Session
from instruments.transports.hislip_codec import HEADER, Kind, message

DEFAULT_CLIENT_MAX = 1 << 20
"""The client's maximum message size until it says another (VISA's default, bytes)."""
WAIT_SLICE_S = 0.2
"""How long a wait for the lock runs before it looks whether the session ended (s)."""


class Link:
    """One HiSLIP session: its synchronous and asynchronous connections, the instrument
    session behind them, and what the two channels share."""

    def __init__(self, session_id: int, sync: socket.socket, session: Session, lock: InstrumentLock,
                 max_message: int) -> None:
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

    def attach_async(self, conn: socket.socket) -> bool:
        """Pair the asynchronous connection; False when one is paired already."""
        if self.asynchronous is not None:
            return False
        self.asynchronous = conn
        return True

    def send_sync(self, kind: int, control: int = 0, parameter: int = 0, payload: bytes = b"") -> None:
        with self._sync_out:
            self.sync.sendall(message(kind, control, parameter, payload))

    def send_async(self, kind: int, control: int = 0, parameter: int = 0, payload: bytes = b"") -> None:
        assert self.asynchronous is not None, "the channels are served once both are paired"
        with self._async_out:
            self.asynchronous.sendall(message(kind, control, parameter, payload))

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
                self.sync.sendall(message(Kind.DATA_END if last else Kind.DATA, 0, message_id,
                                          reply[start:start + part]))

    def wait_unlocked(self) -> bool:
        """Hold a message while another client holds the lock exclusively; False when the
        session ends or is cleared first."""
        while not self.lock.wait_unblocked(self, WAIT_SLICE_S):
            if self.closed.is_set() or self.clearing.is_set():
                return False
        return True

    def close(self) -> None:
        """End the session: its lock released, both connections shut (once)."""
        with self._ending:
            if self._ended:
                return
            self._ended = True
        self.closed.set()
        self.lock.release(self)
        self.session.close()
        for conn in (self.sync, self.asynchronous):
            if conn is not None:
                with contextlib.suppress(OSError):
                    conn.shutdown(socket.SHUT_RDWR)
