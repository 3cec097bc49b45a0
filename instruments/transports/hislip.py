"""An IVI-6.1 HiSLIP server (versions 1.0 to 2.0, synchronized mode, no encryption).

A client opens two TCP connections to one port: the synchronous channel (Initialize, then its
program messages as Data/DataEnd, Trigger, DeviceClearComplete) and the asynchronous channel
(AsyncInitialize with the session id the first got, then locks, status queries, device clear,
the maximum message size, remote/local control). Each pair is one ``Link`` (``hislip_link.py``); the channel
loops are in ``hislip_channels.py``.

Bounded: the largest HiSLIP message taken is the instrument's ``max_message_bytes`` (the
AsyncMaximumMessageSize reply); a longer Data payload gets an Error and is read without being
kept, and a message longer in its Data parts is dropped the same way; either is reported to
the session (``Session.overflow``). Headers without the "HS" prologue and broken
initializations get a FatalError and the connection is closed.

Half-open sessions cannot lock the server: a connection that has not completed its opening
(Initialize, then AsyncInitialize on a second connection) within the half-open timeout is
closed, and when every session is taken a half-open one (the oldest) makes room for a new
Initialize at once; the limits are ``wire.Limits`` (two connections a session), and every
refusal and violation is told to ``on_event``."""
from __future__ import annotations

import contextlib
import itertools
import socket
import threading
from dataclasses import replace

from instruments.transports.addresses import visa_host
from instruments.transports.device import MessageInstrument, Session
from instruments.transports.hislip_channels import serve_async, serve_sync
from instruments.transports.hislip_codec import (
    VERSION_2_0,
    Fatal,
    Kind,
    ProtocolError,
    discard,
    message,
    read_header,
)
from instruments.transports.hislip_link import Link
from instruments.transports.tcp import TcpService, recv_exact
from instruments.transports.wire import Connection, EventKind, EventSink, Limits

VENDOR_ID = int.from_bytes(b"TK", "big")
"""The server's vendor id in AsyncInitializeResponse (the VISA abbreviation of the maker)."""
MAX_SUB_ADDRESS = 256
"""The longest sub-address (device name) read from an Initialize."""


class HislipServer:
    """Serves ``instrument`` over HiSLIP on (host, port) (port 0: a free one, see ``port``);
    ``sub_address`` is the device name of the VISA resource ``TCPIP::host::hislip0,PORT::INSTR``."""

    def __init__(self, instrument: MessageInstrument, host: str = "127.0.0.1", port: int = 0, *,
                 max_sessions: int | None = None, sub_address: str = "hislip0", limits: Limits | None = None,
                 on_event: EventSink | None = None) -> None:
        self.instrument = instrument
        self.sub_address = sub_address
        self._links: dict[int, Link] = {}
        self._guard = threading.Lock()
        self._ids = itertools.cycle(range(1, 0x10000))
        limits = limits or Limits()
        self._max_sessions = limits.max_clients if max_sessions is None else max_sessions
        # two connections a session, and room for one more pair to be refused with a reason
        connections = 2 * self._max_sessions + 2
        self.limits = replace(limits, max_clients=connections, per_address=min(connections, 2 * limits.share + 2))
        self._service = TcpService(self._serve, host, port, name="hislip", limits=self.limits, on_event=on_event,
                                   awaiting="Initialize or AsyncInitialize")
        self.host, self.port = self._service.host, self._service.port

    def start(self) -> HislipServer:
        self._service.start()
        return self

    @property
    def sessions(self) -> int:
        """HiSLIP sessions open now."""
        with self._guard:
            return len(self._links)

    @property
    def resource(self) -> str:
        """The VISA resource string a client opens."""
        return self.resource_at(self.host)

    def resource_at(self, host: str) -> str:
        """The VISA resource string of this server at ``host`` (an address of its machine)."""
        return f"TCPIP::{visa_host(host)}::{self.sub_address},{self.port}::INSTR"

    def _serve(self, conn: socket.socket, peer: str) -> None:
        c = self._service.connection(conn)
        conn.settimeout(self.limits.stall_timeout_s)
        try:
            header = read_header(conn)
        except ProtocolError as e:
            self._fatal(c, Fatal.POORLY_FORMED_HEADER, str(e))
            return
        if header.kind == Kind.INITIALIZE:
            self._initialize(c, peer, header.parameter, header.length)
        elif header.kind == Kind.ASYNC_INITIALIZE:
            discard(conn, header.length)
            self._async_initialize(c, header.parameter)
        else:
            self._fatal(c, Fatal.INVALID_INITIALIZATION,
                        f"first message type = {header.kind}: allowed Initialize (0) or AsyncInitialize (17)")

    def _initialize(self, c: Connection, peer: str, parameter: int, length: int) -> None:
        conn = c.sock
        if length > MAX_SUB_ADDRESS:
            self._fatal(c, Fatal.INVALID_INITIALIZATION,
                        f"sub-address length = {length}: allowed at most {MAX_SUB_ADDRESS} bytes")
            return
        name = recv_exact(conn, length).decode("ascii", "replace")
        if name.lower() != self.sub_address.lower():
            self._fatal(c, Fatal.INVALID_INITIALIZATION, f"sub-address = {name!r}: allowed {self.sub_address!r}")
            return
        link = self._open_link(c, peer)
        if link is None:
            self._fatal(c, Fatal.TOO_MANY_CLIENTS,
                        f"sessions = {self._max_sessions}: allowed at most {self._max_sessions} at once")
            return
        c.awaiting = "AsyncInitialize (the session's second connection)"
        version = min(parameter >> 16, VERSION_2_0)
        link.send_sync(Kind.INITIALIZE_RESPONSE, 0, version << 16 | link.id)  # control 0: synchronized
        try:
            serve_sync(link)
        finally:
            self._close_link(link, c)

    def _open_link(self, c: Connection, peer: str) -> Link | None:
        """A new session for ``c``; where every session is taken, the oldest half-open one
        is closed to make room; None when none is half-open."""
        with self._guard:
            if len(self._links) >= self._max_sessions:
                half_open = [link for link in self._links.values() if link.half_open]
                if not half_open:
                    return None
                victim = min(half_open, key=lambda link: link.watched[0].opened if link.watched else 0.0)
                del self._links[victim.id]
                victim.close(f"evicted: a half-open session (no AsyncInitialize), and all {self._max_sessions} "
                             f"sessions were taken when {peer} initialized")
            session_id = next(i for i in self._ids if i not in self._links)
            session: Session = self.instrument.open_session(peer)
            link = Link(session_id, c.sock, session, self.instrument.lock, self.instrument.max_message_bytes,
                        watch=c, report=lambda text: self._service.report(EventKind.VIOLATION, peer, text))
            self._links[session_id] = link
            return link

    def _async_initialize(self, c: Connection, parameter: int) -> None:
        with self._guard:
            link = self._links.get(parameter & 0xFFFF)
            if link is not None and not link.attach_async(c.sock, c):
                link = None
        if link is None:
            self._fatal(c, Fatal.INVALID_INITIALIZATION,
                        f"session id = {parameter}: allowed the id of an initialized session without an async channel")
            return
        link.send_async(Kind.ASYNC_INITIALIZE_RESPONSE, 0, VENDOR_ID)  # control 0: no encryption
        try:
            serve_async(link)
        finally:
            self._close_link(link, c)

    def _close_link(self, link: Link, by: Connection) -> None:
        with self._guard:
            if self._links.get(link.id) is link:
                del self._links[link.id]
        link.close(by=by)

    def _fatal(self, c: Connection, code: Fatal, text: str) -> None:
        """Send a FatalError and report it (a refusal for too many clients, else a protocol
        violation); the caller then lets the connection close."""
        kind = EventKind.REFUSED if code == Fatal.TOO_MANY_CLIENTS else EventKind.VIOLATION
        self._service.report(kind, c.peer, f"{text}; FatalError sent")
        c.reason = c.reason or ("refused: every session taken" if kind == EventKind.REFUSED else
                                "after the protocol violation")
        with contextlib.suppress(OSError):
            c.sock.sendall(message(Kind.FATAL_ERROR, code, 0, text.encode("ascii", "replace")))

    def close(self) -> None:
        """Stop listening and end every session (their locks are released)."""
        with self._guard:
            links = list(self._links.values())
        for link in links:  # first none may be granted a lock another's end releases
            link.closed.set()
        self._service.close()
        for link in links:
            link.close()

