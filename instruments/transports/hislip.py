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
initializations get a FatalError and the connection is closed."""
from __future__ import annotations

import contextlib
import itertools
import socket
import threading

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

VENDOR_ID = int.from_bytes(b"TK", "big")
"""The server's vendor id in AsyncInitializeResponse (the VISA abbreviation of the maker)."""
MAX_SUB_ADDRESS = 256
"""The longest sub-address (device name) read from an Initialize."""


class HislipServer:
    """Serves ``instrument`` over HiSLIP on (host, port) (port 0: a free one, see ``port``);
    ``sub_address`` is the device name of the VISA resource ``TCPIP::host::hislip0,PORT::INSTR``."""

    def __init__(self, instrument: MessageInstrument, host: str = "127.0.0.1", port: int = 0, *,
                 max_sessions: int = 32, sub_address: str = "hislip0") -> None:
        self.instrument = instrument
        self.sub_address = sub_address
        self._links: dict[int, Link] = {}
        self._guard = threading.Lock()
        self._ids = itertools.cycle(range(1, 0x10000))
        self._max_sessions = max_sessions
        # two connections a session, and room for one more pair to be refused with a reason
        self._service = TcpService(self._serve, host, port, max_clients=2 * max_sessions + 2,
                                   name="hislip")
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
        return f"TCPIP::{self.host}::{self.sub_address},{self.port}::INSTR"

    def _serve(self, conn: socket.socket, peer: str) -> None:
        try:
            header = read_header(conn)
        except ProtocolError as e:
            _fatal(conn, Fatal.POORLY_FORMED_HEADER, str(e))
            return
        if header.kind == Kind.INITIALIZE:
            self._initialize(conn, peer, header.parameter, header.length)
        elif header.kind == Kind.ASYNC_INITIALIZE:
            discard(conn, header.length)
            self._async_initialize(conn, header.parameter)
        else:
            _fatal(conn, Fatal.INVALID_INITIALIZATION,
                   f"first message type = {header.kind}: allowed Initialize (0) or AsyncInitialize (17)")

    def _initialize(self, conn: socket.socket, peer: str, parameter: int, length: int) -> None:
        if length > MAX_SUB_ADDRESS:
            _fatal(conn, Fatal.INVALID_INITIALIZATION,
                   f"sub-address length = {length}: allowed at most {MAX_SUB_ADDRESS} bytes")
            return
        name = recv_exact(conn, length).decode("ascii", "replace")
        if name.lower() != self.sub_address.lower():
            _fatal(conn, Fatal.INVALID_INITIALIZATION, f"sub-address = {name!r}: allowed {self.sub_address!r}")
            return
        link = self._open_link(conn, peer)
        if link is None:
            _fatal(conn, Fatal.TOO_MANY_CLIENTS,
                   f"sessions = {self._max_sessions}: allowed at most {self._max_sessions} at once")
            return
        version = min(parameter >> 16, VERSION_2_0)
        link.send_sync(Kind.INITIALIZE_RESPONSE, 0, version << 16 | link.id)  # control 0: synchronized
        try:
            serve_sync(link)
        finally:
            self._close_link(link)

    def _open_link(self, conn: socket.socket, peer: str) -> Link | None:
        with self._guard:
            if len(self._links) >= self._max_sessions:
                return None
            session_id = next(i for i in self._ids if i not in self._links)
            session: Session = self.instrument.open_session(peer)
            link = Link(session_id, conn, session, self.instrument.lock, self.instrument.max_message_bytes)
            self._links[session_id] = link
            return link

    def _async_initialize(self, conn: socket.socket, parameter: int) -> None:
        with self._guard:
            link = self._links.get(parameter & 0xFFFF)
            if link is not None and not link.attach_async(conn):
                link = None
        if link is None:
            _fatal(conn, Fatal.INVALID_INITIALIZATION,
                   f"session id = {parameter}: allowed the id of an initialized session without an async channel")
            return
        link.send_async(Kind.ASYNC_INITIALIZE_RESPONSE, 0, VENDOR_ID)  # control 0: no encryption
        try:
            serve_async(link)
        finally:
            self._close_link(link)

    def _close_link(self, link: Link) -> None:
        with self._guard:
            self._links.pop(link.id, None)
        link.close()

    def close(self) -> None:
        """Stop listening and end every session (their locks are released)."""
        with self._guard:
            links = list(self._links.values())
        for link in links:  # first none may be granted a lock another's end releases
            link.closed.set()
        self._service.close()
        for link in links:
            link.close()


def _fatal(conn: socket.socket, code: Fatal, text: str) -> None:
    """Send a FatalError; the caller then lets the connection close."""
    with contextlib.suppress(OSError):
        conn.sendall(message(Kind.FATAL_ERROR, code, 0, text.encode("ascii", "replace")))
