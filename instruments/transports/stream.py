"""A streamed reply on a transport that pushes replies (raw socket, HiSLIP): ``Pump`` sends
a session's next responses (``Session.next_reply``: the 4 Series' CURVEStream?) on its
connection, one at a time, while the stream lasts.

The next response is asked for only once the last one has left this machine: its bytes sent
and, where the system tells (Linux: the socket's send queue, SIOCOUTQ), taken by the
client's TCP. A client that stops reading therefore stops the stream's acquisitions once
its receive buffer is full; nothing piles up here. A response already sent when the stream
ends stays in the client's input, as a real scope's does (a raw socket has no device clear:
its clients drain it, VISA's viClear; HiSLIP's clients drop data of an earlier message)."""
from __future__ import annotations

import socket
import struct
import threading
import time
from collections.abc import Callable

from instruments.transports.device import Session
from instruments.transports.wire import Clock

WAIT_S = 0.2
"""How long one wait for the next response or the send queue lasts before the pump looks
whether it was stopped (s)."""
POLL_S = 0.005
"""How often the send queue is looked at while it drains (s)."""

try:  # Linux: bytes in a socket's send queue not yet acknowledged (SIOCOUTQ = TIOCOUTQ)
    import fcntl
    import termios

    def unsent(sock: socket.socket) -> int:
        """Bytes of ``sock``'s send queue the peer has not acknowledged (0 where unknown)."""
        try:
            return struct.unpack("i", fcntl.ioctl(sock.fileno(), termios.TIOCOUTQ, b"\0\0\0\0"))[0]
        except OSError:
            return 0
except ImportError:  # pragma: no cover - elsewhere the send buffer alone bounds what is ahead
    def unsent(sock: socket.socket) -> int:
        return 0


class Pump:
    """Sends ``session``'s streamed responses with ``send(response)`` on ``sock`` in a thread
    of its own until the stream ends, ``stop()`` is called or ``send`` fails (``on_error(exc)``
    is told; the connection is its reader's to close). ``first``: a response already taken;
    ``clock``: the connection's, held busy while the stream lasts (a streaming client sends
    nothing, yet is neither idle nor to be evicted)."""

    def __init__(self, session: Session, sock: socket.socket, send: Callable[[bytes], None],
                 on_error: Callable[[OSError], None] = lambda e: None, name: str = "stream",
                 first: bytes = b"", clock: Clock | None = None) -> None:
        self.session, self.sock, self.send, self.on_error = session, sock, send, on_error
        self._first, self._clock = first, clock or Clock()
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name=name, daemon=True)

    def start(self) -> Pump:
        self._thread.start()
        return self

    def stop(self) -> None:
        """Send nothing after the response being sent (a new message came), and wait for it."""
        self._stop.set()
        if self._thread is not threading.current_thread():
            self._thread.join()

    def _run(self) -> None:
        self._clock.pin(True)
        try:
            self._stream()
        finally:
            self._clock.pin(False)

    def _stream(self) -> None:
        response: bytes | None = self._first
        while not self._stop.is_set():
            if response:
                try:
                    self.send(response)
                except OSError as e:
                    self.on_error(e)
                    return
                while unsent(self.sock) and not self._stop.is_set():  # gone from here before the next is made
                    time.sleep(POLL_S)
                if self._stop.is_set():
                    return
            response = self.session.next_reply(WAIT_S)
            if response is None:
                return


def pump_if_streaming(session: Session, sock: socket.socket, send: Callable[[bytes], None],
                      on_error: Callable[[OSError], None] = lambda e: None, name: str = "stream",
                      clock: Clock | None = None) -> Pump | None:
    """A started Pump where the message just handled began a stream, else None."""
    first = session.next_reply(0.0)
    return None if first is None else Pump(session, sock, send, on_error, name, first, clock).start()
