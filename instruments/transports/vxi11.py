"""VXI-11 (VXIbus Consortium, VXI-11 rev. 1.0, "TCP/IP Instrument Protocol"): the core channel
(program 0x0607AF) and the abort channel (0x0607B0) over ONC RPC, serving any
``MessageInstrument``; VISA's ``TCPIP::host::INSTR`` resource.

A client makes a *link* (``create_link``, device name "inst0"); each link is one ``Session``
of the instrument. ``device_write`` takes a program message in one or more writes, the END
flag marking its last byte; the whole message (at most the instrument's
``max_message_bytes``: a longer one is discarded unread and the session told of its size) is
executed on a thread of its own, so that ``device_read`` (which waits ``io_timeout`` ms for
the response, error 15 past it), ``device_readstb`` and the abort channel keep answering
while a query waits on the instrument. A read returns at most ``request_size`` bytes (and at
most ``MAX_READ_BYTES``) and says why it stopped: END (the response ends), REQCNT (the
requested count), CHR (the termination character, when the client set one). A new message
discards a response left unread (IEEE 488.2 6.3.2.3, query interrupted); the status byte's
MAV bit is the link's: set while a response waits to be read.

Locks are the instrument's ``InstrumentLock``, so a lock taken over VXI-11 holds over HiSLIP
too: an operation on a link while another holds the lock waits ``lock_timeout`` ms when the
client set the wait-lock flag, else fails at once with error 11. The interrupt channel (SRQ)
is not offered: create_intr_chan and device_enable_srq answer error 8, operation not
supported; device_docmd too."""
from __future__ import annotations

import itertools
import select
import socket
import threading
import time
from collections.abc import Callable

from instruments.errors import InstrumentError
from instruments.transports import oncrpc
from instruments.transports.device import MessageInstrument, Session
from instruments.transports.portmap import PMAP_PORT, Announcement, announce
from instruments.transports.tcp import TcpService

DEVICE_CORE_PROG, DEVICE_ASYNC_PROG, VERSION = 0x0607AF, 0x0607B0, 1
(CREATE_LINK, DEVICE_WRITE, DEVICE_READ, DEVICE_READSTB, DEVICE_TRIGGER, DEVICE_CLEAR,
 DEVICE_REMOTE, DEVICE_LOCAL, DEVICE_LOCK, DEVICE_UNLOCK, DEVICE_ENABLE_SRQ) = range(10, 21)
DEVICE_DOCMD, DESTROY_LINK, CREATE_INTR_CHAN, DESTROY_INTR_CHAN = 22, 23, 25, 26
DEVICE_ABORT = 1

# error codes (VXI-11 B.5.2)
NO_ERROR = 0
DEVICE_NOT_ACCESSIBLE = 3
INVALID_LINK = 4
PARAMETER_ERROR = 5
CHANNEL_NOT_ESTABLISHED = 6
OPERATION_NOT_SUPPORTED = 8
OUT_OF_RESOURCES = 9
DEVICE_LOCKED = 11
NO_LOCK_HELD = 12
IO_TIMEOUT = 15
IO_ERROR = 17
ABORT = 23

FLAG_WAIT_LOCK, FLAG_END, FLAG_TERMCHAR = 1, 8, 128
REASON_REQCNT, REASON_CHR, REASON_END = 1, 2, 4
MAV = 0x10
"""Message available: bit 4 of the status byte."""

DEVICE_NAMES = ("inst0",)
MAX_READ_BYTES = 1 << 20
"""The most one device_read returns, whatever it requests (the client reads again)."""
POLL_S = 0.05
"""How often a waiting call looks whether its client is still there."""


class _Link:
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


def _peer_gone(conn: socket.socket) -> bool:
    """True when the client closed its connection (readable, and nothing to read)."""
    try:
        readable, _, _ = select.select([conn], [], [], 0)
        return bool(readable) and conn.recv(1, socket.MSG_PEEK) == b""
    except OSError:
        return True


def _reply(*fields: int, data: bytes | None = None) -> bytes:
    """Packs a response: its integer fields (error first), then the opaque data if any."""
    w = oncrpc.XdrWriter()
    for f in fields:
        w.int(f)
    if data is not None:
        w.opaque(data)
    return bytes(w)


class Vxi11Server:
    """Serves ``instrument`` over VXI-11 on (host, port) (0: a free one; ``port``), with its
    abort channel on ``abort_port``. ``announce()`` makes it findable on port 111;
    ``close()`` ends every link, stops both channels and unregisters it."""

    def __init__(self, instrument: MessageInstrument, host: str = "127.0.0.1", port: int = 0, *,
                 max_recv_size: int = 1 << 16, max_links: int = 64, max_clients: int = 32) -> None:
        self.instrument = instrument
        self.max_recv_size = max_recv_size
        """The largest data one device_write takes (told to the client at create_link)."""
        self._max_links = max_links
        self._links: dict[int, _Link] = {}
        self._guard = threading.Lock()
        self._ids = itertools.count(1)
        try:
            self._core = TcpService(self._serve_core, host, port, max_clients=max_clients, name="vxi11-core")
        except OSError as e:
            raise InstrumentError(f"VXI-11 port = {port}: cannot listen on {host} ({e.strerror}); "
                                  f"allowed: a free port, or 0 for any") from None
        self._abort = TcpService(self._serve_abort, host, 0, max_clients=max_clients, name="vxi11-abort")
        self.host, self.port, self.abort_port = self._core.host, self._core.port, self._abort.port
        self._abort_programs = {DEVICE_ASYNC_PROG: oncrpc.Program(
            DEVICE_ASYNC_PROG, VERSION, VERSION, {DEVICE_ABORT: self._device_abort})}
        self.announcement: Announcement | None = None

    def start(self) -> Vxi11Server:
        self._core.start()
        self._abort.start()
        return self

    @property
    def resource(self) -> str:
        """The VISA resource string: through the portmapper when announced, else with the port."""
        return (f"TCPIP::{self.host}::INSTR" if self.announcement and self.announcement.port == PMAP_PORT
                else f"TCPIP::{self.host},{self.port}::INSTR")

    @property
    def links(self) -> int:
        """Links open now."""
        with self._guard:
            return len(self._links)

    def announce(self, *, start_portmapper: bool = True, portmapper_port: int = PMAP_PORT) -> str:
        """Register the core and abort channels with the portmapper (starting one where none
        answers and ``start_portmapper``); returns how, in words. ``InstrumentError`` when
        neither can be done."""
        self.announcement = announce([(DEVICE_CORE_PROG, VERSION, self.port),
                                      (DEVICE_ASYNC_PROG, VERSION, self.abort_port)],
                                     self.host, port=portmapper_port, start=start_portmapper)
        return self.announcement.how

    def close(self) -> None:
        if self.announcement is not None:
            self.announcement.close()
            self.announcement = None
        self._core.close()
        self._abort.close()
        with self._guard:
            links = list(self._links.values())
        for link in links:
            self._drop(link)

    # ---- channels ------------------------------------------------------------------------

    def _serve_core(self, conn: socket.socket, peer: str) -> None:
        mine: set[int] = set()

        def create_link(r: oncrpc.XdrReader) -> bytes:
            return self._create_link(r, conn, peer, mine)

        def destroy_link(r: oncrpc.XdrReader) -> bytes:
            link_id = r.int()
            r.done()
            mine.discard(link_id)
            return self._destroy_link(link_id)

        procedures = {CREATE_LINK: create_link, DESTROY_LINK: destroy_link,
                      DEVICE_WRITE: self._device_write, DEVICE_READ: self._device_read,
                      DEVICE_READSTB: self._device_readstb, DEVICE_TRIGGER: self._device_trigger,
                      DEVICE_CLEAR: self._device_clear, DEVICE_REMOTE: self._device_remote_local,
                      DEVICE_LOCAL: self._device_remote_local, DEVICE_LOCK: self._device_lock,
                      DEVICE_UNLOCK: self._device_unlock, DEVICE_ENABLE_SRQ: self._device_enable_srq,
                      DEVICE_DOCMD: self._device_docmd, CREATE_INTR_CHAN: self._create_intr_chan,
                      DESTROY_INTR_CHAN: self._destroy_intr_chan}
        programs = {DEVICE_CORE_PROG: oncrpc.Program(DEVICE_CORE_PROG, VERSION, VERSION, procedures)}
        try:  # the largest call is a device_write: its data and at most 1 KiB of headers
            oncrpc.serve_connection(conn, programs, self.max_recv_size + 1024)
        finally:
            for link_id in mine:  # the client is gone: so are its links and its lock
                self._destroy_link(link_id)

    def _serve_abort(self, conn: socket.socket, peer: str) -> None:
        oncrpc.serve_connection(conn, self._abort_programs, 1024)

    # ---- links ---------------------------------------------------------------------------

    def _create_link(self, r: oncrpc.XdrReader, conn: socket.socket, peer: str, mine: set[int]) -> bytes:
        r.int()  # the client's id, for its own bookkeeping
        lock_device, lock_timeout_ms, name = r.bool(), r.uint(), r.string(256)
        r.done()

        def refused(error: int) -> bytes:
            return _reply(error, 0, self.abort_port, self.max_recv_size)

        if name.decode("ascii", "replace").lower() not in DEVICE_NAMES:
            return refused(DEVICE_NOT_ACCESSIBLE)
        link = _Link(next(self._ids), self.instrument.open_session(peer), conn)
        with self._guard:
            full = len(self._links) >= self._max_links
            if not full:
                self._links[link.id] = link
        if full:
            link.session.close()
            return refused(OUT_OF_RESOURCES)
        if lock_device and not self.instrument.lock.acquire(link, timeout_s=lock_timeout_ms / 1000):
            self._drop(link)
            return refused(DEVICE_LOCKED)
        mine.add(link.id)
        return _reply(NO_ERROR, link.id, self.abort_port, self.max_recv_size)

    def _destroy_link(self, link_id: int) -> bytes:
        with self._guard:
            link = self._links.get(link_id)
        if link is None:
            return _reply(INVALID_LINK)
        self._drop(link)
        return _reply(NO_ERROR)

    def _drop(self, link: _Link) -> None:
        with self._guard:
            if self._links.pop(link.id, None) is None:
                return
        with link.cond:
            link.closed = True
            link.cond.notify_all()
        self.instrument.lock.release(link)
        link.session.close()

    def _link(self, link_id: int) -> _Link | None:
        with self._guard:
            return self._links.get(link_id)

    def _await(self, link: _Link, ready: Callable[[], bool], timeout_ms: int) -> int:
        """Wait (holding ``link.cond``) until ``ready()``; the error that ended the wait
        otherwise: 15 past ``timeout_ms``, 23 on device_abort, 17 when the link or its client
        went away."""
        deadline = time.monotonic() + timeout_ms / 1000
        link.in_call = True
        try:
            while not ready():
                if link.closed or _peer_gone(link.conn):
                    return IO_ERROR
                if link.aborted:
                    return ABORT
                left = deadline - time.monotonic()
                if left <= 0:
                    return IO_TIMEOUT
                link.cond.wait(min(left, POLL_S))
            return NO_ERROR
        finally:
            link.in_call = False
            link.aborted = False

    def _lock_free(self, link: _Link, flags: int, lock_timeout_ms: int) -> int:
        """0 when no other link holds the lock (waiting for it with the wait-lock flag), else 11."""
        deadline = time.monotonic() + (lock_timeout_ms / 1000 if flags & FLAG_WAIT_LOCK else 0)
        while self.instrument.lock.blocks(link):
            left = deadline - time.monotonic()
            if left <= 0 or link.closed:
                return DEVICE_LOCKED
            time.sleep(min(left, 0.01))
        return NO_ERROR

    # ---- messages ------------------------------------------------------------------------

    def _device_write(self, r: oncrpc.XdrReader) -> bytes:
        link_id, io_timeout_ms, lock_timeout_ms, flags = r.int(), r.uint(), r.uint(), r.int()
        data = r.opaque(self.max_recv_size + 1024)
        r.done()
        link = self._link(link_id)
        if link is None:
            return _reply(INVALID_LINK, 0)
        if len(data) > self.max_recv_size:
            return _reply(PARAMETER_ERROR, 0)
        error = self._lock_free(link, flags, lock_timeout_ms)
        if error:
            return _reply(error, 0)
        limit = self.instrument.max_message_bytes
        with link.cond:
            if flags & FLAG_END:  # the instrument takes one message at a time
                error = self._await(link, lambda: not link.busy, io_timeout_ms)
                if error:
                    return _reply(error, 0)
            link.message_size += len(data)
            if link.message_size <= limit:
                link.message += data
            else:
                link.message.clear()  # over size: counted, not kept
            if not flags & FLAG_END:
                return _reply(NO_ERROR, len(data))
            size, message = link.message_size, bytes(link.message) if link.message_size <= limit else None
            link.message.clear()
            link.message_size = 0
            link.response, link.read_at = b"", 0  # a new message interrupts an unread response
            link.busy = True
            generation = link.generation
        threading.Thread(target=self._execute, args=(link, message, size, generation),
                         name=f"vxi11-link{link.id}", daemon=True).start()
        return _reply(NO_ERROR, len(data))

    @staticmethod
    def _execute(link: _Link, message: bytes | None, size: int, generation: int) -> None:
        """Run one message (or report one discarded for its size) and queue its response."""
        response = b""
        try:
            if message is None:
                link.session.overflow(size)
            else:
                response = link.session.handle(message)
        finally:
            with link.cond:
                link.busy = False
                if response and link.generation == generation and not link.closed:
                    link.response, link.read_at = response, 0
                link.cond.notify_all()

    def _device_read(self, r: oncrpc.XdrReader) -> bytes:
        link_id, request_size, io_timeout_ms, lock_timeout_ms = r.int(), r.uint(), r.uint(), r.uint()
        flags, term_char = r.int(), r.int()
        r.done()
        link = self._link(link_id)
        if link is None:
            return _reply(INVALID_LINK, 0, data=b"")
        error = self._lock_free(link, flags, lock_timeout_ms)
        if error:
            return _reply(error, 0, data=b"")
        with link.cond:
            error = self._await(link, link.unread, io_timeout_ms)
            if error:
                return _reply(error, 0, data=b"")
            start = link.read_at
            stop = min(len(link.response), start + request_size, start + MAX_READ_BYTES)
            reason = 0
            if flags & FLAG_TERMCHAR:
                found = link.response.find(bytes([term_char & 0xFF]), start, stop)
                if found >= 0:
                    stop, reason = found + 1, REASON_CHR
            data = link.response[start:stop]
            link.read_at = stop
            if stop - start == request_size:
                reason |= REASON_REQCNT
            if stop == len(link.response):
                reason |= REASON_END
                link.response, link.read_at = b"", 0
        return _reply(NO_ERROR, reason, data=data)

    # ---- out of band ---------------------------------------------------------------------

    def _generic(self, r: oncrpc.XdrReader) -> tuple[_Link | None, int, int]:
        """(link, error, io_timeout ms) of the generic parameters: link, flags, lock and io
        timeouts; the error is 4 (no such link) or 11 (locked by another link) or 0."""
        link_id, flags, lock_timeout_ms, io_timeout_ms = r.int(), r.int(), r.uint(), r.uint()
        r.done()
        link = self._link(link_id)
        if link is None:
            return None, INVALID_LINK, io_timeout_ms
        return link, self._lock_free(link, flags, lock_timeout_ms), io_timeout_ms

    def _device_readstb(self, r: oncrpc.XdrReader) -> bytes:
        link, error, _ = self._generic(r)
        if error or link is None:  # no link: error is INVALID_LINK
            return _reply(error, 0)
        with link.cond:
            unread = link.unread()
        return _reply(NO_ERROR, link.session.status_byte() & ~MAV | (MAV if unread else 0))

    def _device_trigger(self, r: oncrpc.XdrReader) -> bytes:
        link, error, io_timeout_ms = self._generic(r)
        if error or link is None:  # no link: error is INVALID_LINK
            return _reply(error)
        with link.cond:  # in order: after the message before it
            error = self._await(link, lambda: not link.busy, io_timeout_ms)
        if not error:
            link.session.trigger()
        return _reply(error)

    def _device_clear(self, r: oncrpc.XdrReader) -> bytes:
        link, error, _ = self._generic(r)
        if error or link is None:  # no link: error is INVALID_LINK
            return _reply(error)
        with link.cond:
            link.generation += 1
            link.message.clear()
            link.message_size = 0
            link.response, link.read_at = b"", 0
        link.session.device_clear()
        return _reply(NO_ERROR)

    def _device_remote_local(self, r: oncrpc.XdrReader) -> bytes:
        """device_remote / device_local: a network instrument has no front-panel lockout to
        switch; answered (after the link and lock checks) with no change."""
        return _reply(self._generic(r)[1])

    def _device_lock(self, r: oncrpc.XdrReader) -> bytes:
        link_id, flags, lock_timeout_ms = r.int(), r.int(), r.uint()
        r.done()
        link = self._link(link_id)
        if link is None:
            return _reply(INVALID_LINK)
        wait_s = lock_timeout_ms / 1000 if flags & FLAG_WAIT_LOCK else 0.0
        return _reply(NO_ERROR if self.instrument.lock.acquire(link, timeout_s=wait_s) else DEVICE_LOCKED)

    def _device_unlock(self, r: oncrpc.XdrReader) -> bytes:
        link_id = r.int()
        r.done()
        link = self._link(link_id)
        if link is None:
            return _reply(INVALID_LINK)
        return _reply(NO_ERROR if self.instrument.lock.release(link) else NO_LOCK_HELD)

    def _device_abort(self, r: oncrpc.XdrReader) -> bytes:
        """The abort channel: ends the link's call in progress (a read or write waiting)
        with error 23; a message already executing runs to its end."""
        link = self._link(r.int())
        r.done()
        if link is None:
            return _reply(INVALID_LINK)
        with link.cond:
            if link.in_call:
                link.aborted = True
                link.cond.notify_all()
        return _reply(NO_ERROR)

    # ---- not offered: the interrupt channel and docmd ------------------------------------

    def _device_enable_srq(self, r: oncrpc.XdrReader) -> bytes:
        r.int(), r.bool(), r.opaque(40)
        r.done()
        return _reply(OPERATION_NOT_SUPPORTED)

    def _device_docmd(self, r: oncrpc.XdrReader) -> bytes:
        r.int(), r.int(), r.uint(), r.uint(), r.int(), r.bool(), r.int(), r.opaque(self.max_recv_size)
        r.done()
        return _reply(OPERATION_NOT_SUPPORTED, data=b"")

    def _create_intr_chan(self, r: oncrpc.XdrReader) -> bytes:
        r.uint(), r.uint(), r.uint(), r.uint(), r.int()
        r.done()
        return _reply(OPERATION_NOT_SUPPORTED)

    def _destroy_intr_chan(self, r: oncrpc.XdrReader) -> bytes:
        r.done()
        return _reply(CHANNEL_NOT_ESTABLISHED)
