"""The raw-socket server of a Tektronix scope (port 4000 on a real one, protocol NONe).

A program message ends in a newline (``\\r\\n`` is taken too); it may arrive in pieces, and one
``recv`` may hold several. A newline inside a quoted string or an IEEE 488.2 definite-length
block (``#<n><length><bytes>``) is data, not a terminator, so binary blocks may be written.
Each reply is sent as the instrument gives it (it ends in ``\\n``); a command without a query
sends nothing back. Memory is bounded: a message longer than the instrument's
``max_message_bytes`` is read to its terminator without being kept, and the session is told
(``Session.overflow``).

The scope's socket server also has a TERMinal protocol (a prompt and ``!``-commands such as
``!d``, device clear, for people typing at telnet); VISA clients use protocol NONe, which has
no out-of-band messages, so none is read here: a socket client clears with ``*CLS``."""
from __future__ import annotations

import re
import socket
import threading

from instruments.transports.device import MessageInstrument
from instruments.transports.tcp import TcpService

_SPECIAL = re.compile(rb"[\n\"'#]")
"""What changes the framer's state outside strings and blocks."""


class MessageFramer:
    """Cuts a byte stream into program messages, keeping at most ``limit`` bytes of one.

    ``feed(chunk)`` returns, in order, each message completed by the chunk (bytes, its
    terminator removed) or, for one over the limit, its size in bytes (an int)."""

    def __init__(self, limit: int) -> None:
        self.limit = limit
        self._kept = bytearray()
        self._size = 0          # bytes of the current message so far (kept or not)
        self._quote = b""       # the open quote character inside a string
        self._hash = False      # a '#' was the last byte: a block may follow
        self._digits = -1       # digits of a block's length still to read (-1: none)
        self._length = 0        # the block's length read so far
        self._block = 0         # bytes of the block still to pass over
        self._block_end = 0     # where the last block ended in the message (a '\r' in it is data)

    def feed(self, chunk: bytes) -> list[bytes | int]:
        out: list[bytes | int] = []
        view, i, n = memoryview(chunk), 0, len(chunk)
        while i < n:
            j = self._scan(chunk, i)
            if j is None:  # the chunk ends inside the message
                self._take(view[i:])
                break
            self._take(view[i:j])  # up to, not including, the terminator at j
            out.append(self._finish())
            i = j + 1
        return out

    def _scan(self, chunk: bytes, i: int) -> int | None:
        """The index of the terminating newline at or after ``i``, or None; updates the
        lexical state over what it passes."""
        n, base = len(chunk), self._size - i  # base + index: the offset in the message
        while i < n:
            if self._block:
                step = min(self._block, n - i)
                self._block -= step
                i += step
                self._block_end = base + i
            elif self._digits >= 0:
                i = self._length_digit(chunk[i], i)
            elif self._hash:
                self._hash = False
                if 0x31 <= chunk[i] <= 0x39:  # '#1'..'#9': a definite-length block
                    self._digits, self._length = chunk[i] - 0x30, 0
                    i += 1
            elif self._quote:
                end = chunk.find(self._quote, i)
                if end < 0:
                    return None
                self._quote, i = b"", end + 1  # a doubled quote reopens at once: same result
            else:
                m = _SPECIAL.search(chunk, i)
                if m is None:
                    return None
                c, i = chunk[m.start():m.start() + 1], m.start() + 1
                if c == b"\n":
                    return m.start()
                if c == b"#":
                    self._hash = True
                else:
                    self._quote = c
        return None

    def _length_digit(self, byte: int, i: int) -> int:
        """Read one digit of a block's length at ``i``; the index to go on from."""
        if not 0x30 <= byte <= 0x39:  # not a block after all: lex the byte normally
            self._digits = -1
            return i
        self._length = self._length * 10 + byte - 0x30
        self._digits -= 1
        if self._digits == 0:
            self._digits, self._block = -1, self._length
        return i + 1

    def _take(self, part: memoryview) -> None:
        self._size += len(part)
        if self._size <= self.limit:
            self._kept += part
        else:
            self._kept.clear()

    def _finish(self) -> bytes | int:
        size, message, block_end = self._size, bytes(self._kept), self._block_end
        self._kept.clear()
        self._size, self._quote, self._hash, self._digits, self._block, self._block_end = 0, b"", False, -1, 0, 0
        if size > self.limit:
            return size
        return message[:-1] if message.endswith(b"\r") and size > block_end else message


class SocketServer:
    """Serves ``instrument`` on a raw TCP socket (port 0: a free one, see ``port``)."""

    def __init__(self, instrument: MessageInstrument, host: str = "127.0.0.1", port: int = 0, *,
                 max_clients: int = 32) -> None:
        self.instrument = instrument
        self._stop = threading.Event()
        self._service = TcpService(self._serve, host, port, max_clients=max_clients, name="socket")
        self.host, self.port = self._service.host, self._service.port

    def start(self) -> SocketServer:
        self._service.start()
        return self

    @property
    def clients(self) -> int:
        """Connections open now."""
        return self._service.clients

    @property
    def resource(self) -> str:
        """The VISA resource string a client opens."""
        return f"TCPIP::{self.host}::{self.port}::SOCKET"

    def _serve(self, conn: socket.socket, peer: str) -> None:
        session = self.instrument.open_session(peer)
        framer = MessageFramer(self.instrument.max_message_bytes)
        owner = object()  # a socket client never holds the lock; it waits while another does
        try:
            while chunk := conn.recv(1 << 16):
                for message in framer.feed(chunk):
                    if isinstance(message, int):
                        session.overflow(message)
                        continue
                    if not message or not self._wait_unlocked(owner):
                        continue
                    reply = session.handle(message)
                    if reply:
                        conn.sendall(reply)
        finally:
            session.close()

    def _wait_unlocked(self, owner: object) -> bool:
        """Hold the message while another client holds the lock exclusively; False when the
        server stops first."""
        while not self.instrument.lock.wait_unblocked(owner, 0.2):
            if self._stop.is_set():
                return False
        return not self._stop.is_set()

    def close(self) -> None:
        """Stop listening and drop every connection."""
        self._stop.set()
        self._service.close()
