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
supported; device_docmd too.

This module is the server: its two channels, the links' table, create_link and
destroy_link. The numbers and the replies' packing are ``vxi11_codec``'s, a link and its waits
``vxi11_link``'s, the procedures on a link ``vxi11_procedures``'s."""
from __future__ import annotations

import itertools
import socket
import threading

from instruments.errors import InstrumentError
from instruments.transports import oncrpc
from instruments.transports.addresses import visa_host
from instruments.transports.device import MessageInstrument
from instruments.transports.portmap import PMAP_PORT, Announcement, announce
from instruments.transports.tcp import TcpService
from instruments.transports.vxi11_codec import (
    CREATE_LINK,
    DESTROY_LINK,
    DEVICE_ABORT,
    DEVICE_ASYNC_PROG,
    DEVICE_CORE_PROG,
    DEVICE_LOCKED,
    DEVICE_NOT_ACCESSIBLE,
    INVALID_LINK,
    NO_ERROR,
    OUT_OF_RESOURCES,
    VERSION,
    reply,
)
from instruments.transports.vxi11_link import Link
from instruments.transports.vxi11_procedures import LinkProcedures
from instruments.transports.wire import EventKind, EventSink, Limits

__all__ = ["DEVICE_NAMES", "Vxi11Server"]

DEVICE_NAMES = ("inst0",)


class Vxi11Server:
    """Serves ``instrument`` over VXI-11 on (host, port) (0: a free one; ``port``), with its
    abort channel on ``abort_port``. ``announce()`` makes it findable on port 111;
    ``close()`` ends every link, stops both channels and unregisters it."""

    def __init__(self, instrument: MessageInstrument, host: str = "127.0.0.1", port: int = 0, *,
                 max_recv_size: int = 1 << 16, max_links: int = 64, max_clients: int | None = None,
                 limits: Limits | None = None, on_event: EventSink | None = None) -> None:
        self.instrument = instrument
        self.max_recv_size = max_recv_size
        """The largest data one device_write takes (told to the client at create_link)."""
        self._max_links = max_links
        self._links: dict[int, Link] = {}
        self._guard = threading.Lock()
        self._ids = itertools.count(1)
        self._on_event = on_event
        try:
            self._core = TcpService(self._serve_core, host, port, max_clients=max_clients, name="vxi11-core",
                                    limits=limits, on_event=on_event)
        except OSError as e:
            raise InstrumentError(f"VXI-11 port = {port}: cannot listen on {host} ({e.strerror}); "
                                  f"allowed: a free port, or 0 for any") from None
        self.limits = self._core.limits
        try:
            self._abort = TcpService(self._serve_abort, self._core.host, 0, name="vxi11-abort", limits=self.limits,
                                     on_event=on_event)
        except OSError:
            self._core.close()
            raise
        self.host, self.port, self.abort_port = self._core.host, self._core.port, self._abort.port
        self._procedures = LinkProcedures(instrument, self._link, max_recv_size)
        self._abort_programs = {DEVICE_ASYNC_PROG: oncrpc.Program(
            DEVICE_ASYNC_PROG, VERSION, VERSION, {DEVICE_ABORT: self._procedures.device_abort})}
        self.announcement: Announcement | None = None

    def start(self) -> Vxi11Server:
        self._core.start()
        self._abort.start()
        return self

    @property
    def resource(self) -> str:
        """The VISA resource string: through the portmapper when announced, else with the port."""
        return self.resource_at(self.host)

    def resource_at(self, host: str, *, by_port: bool = False) -> str:
        """The VISA resource string of this server at ``host`` (an address of its machine):
        through the portmapper when announced on port 111 (unless ``by_port``), else with the
        core channel's port."""
        announced = self.announcement is not None and self.announcement.port == PMAP_PORT
        return (f"TCPIP::{visa_host(host)}::INSTR" if announced and not by_port
                else f"TCPIP::{visa_host(host)},{self.port}::INSTR")

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
                                     self.host, port=portmapper_port, start=start_portmapper,
                                     on_event=self._on_event)
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

        procedures = {CREATE_LINK: create_link, DESTROY_LINK: destroy_link, **self._procedures.core}
        programs = {DEVICE_CORE_PROG: oncrpc.Program(DEVICE_CORE_PROG, VERSION, VERSION, procedures)}
        conn.settimeout(self.limits.stall_timeout_s)
        try:  # the largest call is a device_write: its data and at most 1 KiB of headers
            oncrpc.serve_connection(conn, programs, self.max_recv_size + 1024, self._core.connection(conn))
        finally:
            for link_id in mine:  # the client is gone: so are its links and its lock
                self._destroy_link(link_id)

    def _serve_abort(self, conn: socket.socket, peer: str) -> None:
        conn.settimeout(self.limits.stall_timeout_s)
        oncrpc.serve_connection(conn, self._abort_programs, 1024, self._abort.connection(conn))

    # ---- links ---------------------------------------------------------------------------

    def _create_link(self, r: oncrpc.XdrReader, conn: socket.socket, peer: str, mine: set[int]) -> bytes:
        r.int()  # the client's id, for its own bookkeeping
        lock_device, lock_timeout_ms, name = r.bool(), r.uint(), r.string(256)
        r.done()

        def refused(error: int, why: str) -> bytes:
            self._core.report(EventKind.REFUSED, peer, f"create_link: {why} (VXI-11 error {error})")
            return reply(error, 0, self.abort_port, self.max_recv_size)

        device = name.decode("ascii", "replace")
        if device.lower() not in DEVICE_NAMES:
            return refused(DEVICE_NOT_ACCESSIBLE, f"device name {device!r}: allowed {', '.join(DEVICE_NAMES)}")
        link = Link(next(self._ids), self.instrument.open_session(peer), conn)
        with self._guard:
            full = len(self._links) >= self._max_links
            if not full:
                self._links[link.id] = link
        if full:
            link.session.close()
            return refused(OUT_OF_RESOURCES, f"{self._max_links} links open: allowed at most {self._max_links}")
        if lock_device and not self.instrument.lock.acquire(link, timeout_s=lock_timeout_ms / 1000):
            self._drop(link)
            return refused(DEVICE_LOCKED, f"the lock asked with the link is held by another client after "
                                          f"{lock_timeout_ms} ms")
        mine.add(link.id)
        return reply(NO_ERROR, link.id, self.abort_port, self.max_recv_size)

    def _destroy_link(self, link_id: int) -> bytes:
        with self._guard:
            link = self._links.get(link_id)
        if link is None:
            return reply(INVALID_LINK)
        self._drop(link)
        return reply(NO_ERROR)

    def _drop(self, link: Link) -> None:
        with self._guard:
            if self._links.pop(link.id, None) is None:
                return
        with link.cond:
            link.closed = True
            link.cond.notify_all()
        self.instrument.lock.release(link)
        link.session.close()

    def _link(self, link_id: int) -> Link | None:
        with self._guard:
            return self._links.get(link_id)
