"""One VXI-11 link: its instrument session, the program message being written, the response
being read, and the waits of a call on it (for the response, for the instrument's lock)."""
from __future__ import annotations

import select
import socket
import threading
import time
from collections.abc import Callable

from instruments.transports.device import InstrumentLock, Session
from instruments.transports.vxi11_codec import ABORT, DEVICE_LOCKED, FLAG_WAIT_LOCK, IO_ERROR, IO_TIMEOUT, NO_ERROR

POLL_S = 0.05
"""How often a waiting call looks whether its client is still there (s)."""


def peer_gone(conn: socket.socket) -> bool:
    """True when the client closed its connection (readable, and nothing to read)."""
    try:
        readable, _, _ = select.select([conn], [], [], 0)
        return bool(readable) and conn.recv(1, socket.MSG_PEEK) == b""
    except OSError:
        return True


class Link:
    """One link: its session, the message being written, the response being read."""

    def __init__(self, link_id: int, session: Session, conn: socket.socket) -> None:
        self.id, self.session, self.conn = link_id, session, conn
        self.cond = threading.Condition()
        self.message = bytearray()
        self.message_size = 0  # bytes written since the last END, kept or not
        self.response, self.read_at = b"", 0
        self.busy = False  # a message is executing
        self.generation = 0  # bumped by device_clear: a running message's response is dropped
        self.in_call = False
        self.aborted = False
        self.closed = False

    def unread(self) -> bool:
        return self.read_at < len(self.response)

    def streamed(self) -> bool:
        """unread(), after taking a streamed reply's next response where nothing is left to
        read and no message runs (holding ``cond``; Session.next_reply, without waiting: a
        read's wait asks again)."""
        if not self.unread() and not self.busy:
            response = self.session.next_reply(0.0)
            if response:
                self.response, self.read_at = response, 0
        return self.unread()

    def wait(self, ready: Callable[[], bool], timeout_ms: int) -> int:
        """Wait (holding ``cond``) until ``ready()``; the error that ended the wait
        otherwise: 15 past ``timeout_ms``, 23 on device_abort, 17 when the link or its client
        went away."""
        deadline = time.monotonic() + timeout_ms / 1000
        self.in_call = True
        try:
            while not ready():
                if self.closed or peer_gone(self.conn):
                    return IO_ERROR
                if self.aborted:
                    return ABORT
                left = deadline - time.monotonic()
                if left <= 0:
                    return IO_TIMEOUT
                self.cond.wait(min(left, POLL_S))
            return NO_ERROR
        finally:
            self.in_call = False
            self.aborted = False

    def lock_free(self, lock: InstrumentLock, flags: int, lock_timeout_ms: int) -> int:
        """0 when no other link holds ``lock`` (waiting for it with the wait-lock flag), else 11."""
        deadline = time.monotonic() + (lock_timeout_ms / 1000 if flags & FLAG_WAIT_LOCK else 0)
        while lock.blocks(self):
            left = deadline - time.monotonic()
            if left <= 0 or self.closed:
                return DEVICE_LOCKED
            time.sleep(min(left, 0.01))
        return NO_ERROR

    def execute(self, message: bytes | None, size: int, generation: int) -> None:
        """Run one message (or report one of ``size`` bytes discarded for its size) and queue
        its response, unless a device_clear (a new ``generation``) or the link's end came first."""
        response = b""
        try:
            if message is None:
                self.session.overflow(size)
            else:
                response = self.session.handle(message)
        finally:
            with self.cond:
                self.busy = False
                if response and self.generation == generation and not self.closed:
                    self.response, self.read_at = response, 0
                self.cond.notify_all()
