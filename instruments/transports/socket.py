"""The raw-socket server of a Tektronix scope (port 4000 on a real one, protocol NONe).

A program message ends in a newline (``\\r\\n`` is taken too); it may arrive in pieces, and one
``recv`` may hold several. A newline inside a quoted string or an IEEE 488.2 definite-length
block (``#<n><length><bytes>``) is data, not a terminator, so binary blocks may be written.
Each reply is sent as the instrument gives it (it ends in ``\\n``); a command without a query
sends nothing back. Memory is bounded: a message longer than the instrument's
``max_message_bytes`` is read to its terminator without being kept, and the session is told
(``Session.overflow``); a block length is never trusted past that limit, and a block whose
bytes stop for the stall timeout is dropped (``MessageFramer``), so that a lying length
swallows no later message for long.

The scope's socket server also has a TERMinal protocol (a prompt and ``!``-commands such as
``!d``, device clear, for people typing at telnet); VISA clients use protocol NONe, which has
no out-of-band messages, so none is read here: a socket client clears with ``*CLS``. A
streamed reply (CURVEStream?) is sent block after block by a ``stream.Pump`` while the
reader goes on; the client's next message stops it before that message runs."""
from __future__ import annotations

import re
import socket
import threading

from instruments.transports.addresses import visa_host
from instruments.transports.device import MessageInstrument, Session
from instruments.transports.stream import Pump, pump_if_streaming
from instruments.transports.tcp import TcpService, send_all
from instruments.transports.wire import Connection, EventKind, EventSink, Limits

_SPECIAL = re.compile(rb"[\n\"'#]")
"""What changes the framer's state outside strings and blocks."""


class MessageFramer:
    """Cuts a byte stream into program messages, keeping at most ``limit`` bytes of one.

    ``feed(chunk)`` returns, in order, each message completed by the chunk (bytes, its
    terminator removed) or, for one over the limit, its size in bytes (an int: the bytes it
    had, or as many as a block in it claimed, whichever is more).

    Bounded by the limit, whatever the client claims: once a message holds more than
    ``limit`` bytes, strings and blocks no longer hide a newline, and the next newline ends
    it; a definite-length block whose length would take its message past the limit is not
    followed at all (its message is over the limit from there, and ends at the next
    newline), so a block length that lies swallows no message after it. A block whose bytes
    stop coming is ended by the server (``abandon``)."""

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
        self._over = False      # the message is over the limit: the next newline ends it
        self._claimed = 0       # the size a block of it claimed the message has

    @property
    def in_block(self) -> bool:
        """True while the bytes of a definite-length block are still to come."""
        return self._block > 0

    @property
    def pending(self) -> int:
        """Bytes of a message begun and not ended."""
        return self._size

    def feed(self, chunk: bytes) -> list[bytes | int]:
        out: list[bytes | int] = []
        view, i, n = memoryview(chunk), 0, len(chunk)
        while i < n:
            if self._over:
                j = chunk.find(b"\n", i)
                if j < 0:
                    self._take(view[i:])
                    break
                self._take(view[i:j])
                out.append(self._finish())
                i = j + 1
                continue
            stop = min(n, i + self.limit - self._size + 1)  # up to the byte at offset `limit`
            end, found = self._scan(chunk, i, stop)
            self._take(view[i:end])
            if found:
                out.append(self._finish())
                end += 1
            elif self._size > self.limit:
                self._over = True
            i = end
        return out

    def abandon(self) -> int:
        """Drop the message begun (its block stopped coming); the bytes it had."""
        size = self._size
        self._reset()
        return size

    def _scan(self, chunk: bytes, i: int, stop: int) -> tuple[int, bool]:
        """(index of the terminating newline, True) at or after ``i`` and before ``stop``, or
        (where the scan stopped, False); updates the lexical state over what it passes. A
        block claiming more than the limit allows stops the scan after its header, the
        message over the limit."""
        base = self._size - i  # base + index: the offset in the message
        while i < stop:
            if self._block:
                step = min(self._block, stop - i)
                self._block -= step
                i += step
                self._block_end = base + i
            elif self._digits >= 0:
                i = self._length_digit(chunk[i], i)
                if self._block and base + i + self._block > self.limit:  # a length that cannot be kept
                    self._over, self._claimed, self._block = True, base + i + self._block, 0
                    return i, False
            elif self._hash:
                self._hash = False
                if 0x31 <= chunk[i] <= 0x39:  # '#1'..'#9': a definite-length block
                    self._digits, self._length = chunk[i] - 0x30, 0
                    i += 1
            elif self._quote:
                end = chunk.find(self._quote, i, stop)
                if end < 0:
                    return stop, False
                self._quote, i = b"", end + 1  # a doubled quote reopens at once: same result
            else:
                m = _SPECIAL.search(chunk, i, stop)
                if m is None:
                    return stop, False
                c, i = chunk[m.start():m.start() + 1], m.start() + 1
                if c == b"\n":
                    return m.start(), True
                if c == b"#":
                    self._hash = True
                else:
                    self._quote = c
        return stop, False

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
        if self._size <= self.limit and not self._over:
            self._kept += part
        else:
            self._kept.clear()

    def _finish(self) -> bytes | int:
        size, message, block_end, over = self._size, bytes(self._kept), self._block_end, self._over
        claimed = self._claimed
        self._reset()
        if over or size > self.limit:
            return max(size, claimed)
        return message[:-1] if message.endswith(b"\r") and size > block_end else message

    def _reset(self) -> None:
        self._kept.clear()
        self._size, self._quote, self._hash, self._digits, self._block, self._block_end = 0, b"", False, -1, 0, 0
        self._over, self._claimed = False, 0


class SocketServer:
    """Serves ``instrument`` on a raw TCP socket (port 0: a free one, see ``port``), within
    ``limits`` (``wire.Limits``), telling ``on_event`` of each connection, end, refusal and
    protocol violation (a message over the limit, a block that stopped coming)."""

    def __init__(self, instrument: MessageInstrument, host: str = "127.0.0.1", port: int = 0, *,
                 max_clients: int | None = None, limits: Limits | None = None,
                 on_event: EventSink | None = None, name: str = "socket") -> None:
        self.instrument = instrument
        self._stop = threading.Event()
        self._service = TcpService(self._serve, host, port, max_clients=max_clients, name=name, limits=limits,
                                   on_event=on_event)
        self.limits = self._service.limits
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
        return self.resource_at(self.host)

    def resource_at(self, host: str) -> str:
        """The VISA resource string of this server at ``host`` (an address of its machine)."""
        return f"TCPIP::{visa_host(host)}::{self.port}::SOCKET"

    def _serve(self, conn: socket.socket, peer: str) -> None:
        c = self._service.connection(conn)
        session = self.instrument.open_session(peer)
        limit = self.instrument.max_message_bytes
        framer = MessageFramer(limit)
        owner = object()  # a socket client never holds the lock; it waits while another does
        conn.settimeout(self.limits.stall_timeout_s)
        pump: Pump | None = None
        try:
            while True:
                try:
                    chunk = conn.recv(1 << 16)
                except TimeoutError:  # a pause: the end of a block that stopped coming, else nothing
                    if framer.in_block:
                        size = framer.abandon()
                        self._service.report(EventKind.VIOLATION, peer, (
                            f"a definite-length block stopped coming: no byte for {self.limits.stall_timeout_s:g} s; "
                            f"its message ({size} bytes so far) is dropped and the next byte starts a new one"))
                    continue
                if not chunk:
                    break
                c.clock.heard()
                for message in framer.feed(chunk):
                    if pump is not None and isinstance(message, bytes) and message:
                        pump.stop()  # the client's next message ends its stream
                        pump = None
                    if self._execute(message, session, conn, c, owner, peer, limit):
                        pump = pump_if_streaming(session, conn, lambda r: send_all(conn, r),
                                                 lambda e: self._stalled(c, peer), f"{self._service.name}-stream",
                                                 c.clock)
        finally:
            if pump is not None:
                pump.stop()
            session.close()

    def _stalled(self, c: Connection, peer: str) -> None:
        """A streamed reply not taken within the stall timeout: the connection ends."""
        self._service.report(EventKind.VIOLATION, peer, f"stalled: a streamed reply made no progress for "
                                                        f"{self.limits.stall_timeout_s:g} s")
        c.close("stalled")

    def _execute(self, message: bytes | int, session: Session, conn: socket.socket, c: Connection, owner: object,
                 peer: str, limit: int) -> bool:
        """One message the framer cut: refused for its size, or run and its reply sent; True
        when it ran."""
        if isinstance(message, int):
            session.overflow(message)
            self._service.report(EventKind.VIOLATION, peer, f"a program message of {message} bytes (a block's "
                                                            f"claim included): allowed at most {limit}; refused")
            c.clock.done()
            return False
        if not message:
            return False
        with c.clock.working():
            if not self._wait_unlocked(owner):
                return False
            reply = session.handle(message)
        if reply:
            send_all(conn, reply)
            c.clock.done()
        return True

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
