"""ONC RPC version 2 (RFC 5531) over TCP and UDP, as much of it as VXI-11 and the portmapper
need, with the stdlib only: an XDR codec (RFC 4506: 4-byte big-endian units, opaque data
padded to 4 bytes), TCP record marking (a 4-byte header per fragment: bit 31 = last
fragment, bits 0-30 = its length in bytes), call and reply headers, AUTH_NONE verifiers.

A server is a set of ``Program``s; ``answer`` turns one call record into its reply record:
PROG_UNAVAIL, PROG_MISMATCH, PROC_UNAVAIL and GARBAGE_ARGS as RFC 5531 gives them, and
RPC_MISMATCH for a caller that speaks another RPC version. Every length read off the wire is
bounded before anything is allocated: a record fragment over the connection's limit is a
protocol violation (``RecordTooLarge``) on which the connection is closed unread.
``RpcClient`` calls over one connection it keeps (a portmapper registration lives as long
as the connection that made it)."""
from __future__ import annotations

import builtins
import itertools
import socket
import struct
import threading
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field

from instruments.transports.tcp import ProtocolViolation, await_message, recv_exact, send_all
from instruments.transports.wire import Connection

RPC_VERSION = 2
CALL, REPLY = 0, 1
MSG_ACCEPTED, MSG_DENIED = 0, 1
SUCCESS, PROG_UNAVAIL, PROG_MISMATCH, PROC_UNAVAIL, GARBAGE_ARGS, SYSTEM_ERR = range(6)
RPC_MISMATCH = 0
AUTH_NONE = 0
MAX_AUTH_BYTES = 400
"""RFC 5531 9: a credential or verifier body holds at most 400 bytes."""
LAST_FRAGMENT = 0x8000_0000


class XdrError(ValueError):
    """Data that does not decode as the XDR the procedure takes (short, or a length over its
    bound); the server answers GARBAGE_ARGS."""


class RecordTooLarge(ProtocolViolation):
    """A TCP record (or one of its fragments) longer than the connection allows."""


class RpcError(ConnectionError):
    """A call the server did not accept (its reply status, in words)."""


class XdrWriter:
    """Packs XDR items into one buffer (``bytes()`` gives it)."""

    def __init__(self) -> None:
        self._parts: list[bytes] = []

    def uint(self, value: int) -> XdrWriter:
        self._parts.append(struct.pack(">I", value & 0xFFFF_FFFF))
        return self

    def int(self, value: int) -> XdrWriter:
        self._parts.append(struct.pack(">i", value))
        return self

    def bool(self, value: bool) -> XdrWriter:
        return self.uint(1 if value else 0)

    def opaque(self, data: bytes) -> XdrWriter:
        """Variable-length opaque data (and ``string``): its length, the bytes, zero padding."""
        self.uint(len(data))
        self._parts.append(bytes(data))
        self._parts.append(b"\0" * (-len(data) % 4))
        return self

    string = opaque

    def raw(self, data: bytes) -> XdrWriter:
        """Bytes already in XDR (a nested item packed elsewhere)."""
        self._parts.append(bytes(data))
        return self

    def __bytes__(self) -> bytes:
        return b"".join(self._parts)


class XdrReader:
    """Unpacks XDR items from one buffer; every read past its end raises ``XdrError``."""

    def __init__(self, data: bytes) -> None:
        self._data = memoryview(data)
        self._pos = 0

    def _take(self, n: int) -> bytes:
        if n > len(self._data) - self._pos:
            raise XdrError(f"XDR data ends {n - (len(self._data) - self._pos)} bytes early")
        chunk = self._data[self._pos:self._pos + n].tobytes()
        self._pos += n
        return chunk

    def uint(self) -> int:
        return struct.unpack(">I", self._take(4))[0]

    def int(self) -> int:
        return struct.unpack(">i", self._take(4))[0]

    def bool(self) -> bool:
        value = self.uint()
        if value > 1:
            raise XdrError(f"XDR bool = {value}: allowed 0 or 1")
        return value == 1

    def opaque(self, max_bytes: builtins.int = 0xFFFF_FFFF) -> bytes:
        """Variable-length opaque data of at most ``max_bytes`` (checked before reading)."""
        n = self.uint()
        if n > max_bytes:
            raise XdrError(f"XDR opaque length = {n}: allowed at most {max_bytes} bytes")
        data = self._take(n)
        self._take(-n % 4)
        return data

    string = opaque

    @property
    def remaining(self) -> builtins.int:
        """Bytes not read yet."""
        return len(self._data) - self._pos

    def done(self) -> None:
        """Raise ``XdrError`` when bytes are left over (arguments longer than the procedure's)."""
        if self.remaining:
            raise XdrError(f"{self.remaining} bytes after the last XDR item")


# ---- record marking (RFC 5531 11) ----------------------------------------------------------

def read_record(conn: socket.socket, max_bytes: int) -> bytes:
    """One whole record from a TCP stream: its fragments joined. A fragment or record over
    ``max_bytes`` raises ``RecordTooLarge`` before its body is read; a peer that closes
    raises ``ConnectionError``."""
    parts, total, last = [], 0, False
    while not last:
        (header,) = struct.unpack(">I", recv_exact(conn, 4))
        last, size = bool(header & LAST_FRAGMENT), header & ~LAST_FRAGMENT
        total += size
        if total > max_bytes:
            raise RecordTooLarge(f"record of at least {total} bytes: allowed at most {max_bytes}")
        parts.append(recv_exact(conn, size))
    return b"".join(parts)


def write_record(conn: socket.socket, record: bytes) -> None:
    """Send ``record`` as one last fragment."""
    send_all(conn, struct.pack(">I", LAST_FRAGMENT | len(record)) + record)


# ---- calls and replies ---------------------------------------------------------------------

@dataclass(frozen=True)
class Call:
    """A call header (RFC 5531 9): the transaction id, program, version and procedure."""

    xid: int
    prog: int
    vers: int
    proc: int


Procedure = Callable[[XdrReader], bytes]
"""Unpacks its arguments from the reader (``XdrError`` when they do not decode) and returns
its packed result."""


@dataclass(frozen=True)
class Program:
    """One RPC program a server answers: its number, the versions it speaks (low, high) and
    its procedures by number (procedure 0, NULL, is answered for every program)."""

    number: int
    low: int
    high: int
    procedures: Mapping[int, Procedure] = field(default_factory=dict)


def _accepted(xid: int, status: int, body: bytes = b"") -> bytes:
    return bytes(XdrWriter().uint(xid).uint(REPLY).uint(MSG_ACCEPTED)
                 .uint(AUTH_NONE).opaque(b"").uint(status).raw(body))


class _WrongRpcVersion(XdrError):
    def __init__(self, call: Call) -> None:
        super().__init__(f"RPC version: allowed {RPC_VERSION}")
        self.call = call


def read_call(record: bytes) -> tuple[Call, XdrReader]:
    """The call header of ``record`` and a reader at its arguments. The credential and
    verifier are read and ignored (a server may, RFC 5531 8.2: this one grants every caller
    the same access). Raises ``XdrError`` on a record that is not a call."""
    r = XdrReader(record)
    xid, kind = r.uint(), r.uint()
    if kind != CALL:
        raise XdrError(f"RPC message type = {kind}: a server takes calls (0)")
    rpcvers = r.uint()
    call = Call(xid, r.uint(), r.uint(), r.uint())
    for _ in ("credential", "verifier"):
        r.uint()
        r.opaque(MAX_AUTH_BYTES)
    if rpcvers != RPC_VERSION:
        raise _WrongRpcVersion(call)
    return call, r


def answer(record: bytes, programs: Mapping[int, Program]) -> bytes | None:
    """The reply record to one call record, or None when the record is no call to answer
    (too short to hold a header, or a reply)."""
    try:
        call, args = read_call(record)
    except _WrongRpcVersion as e:
        return bytes(XdrWriter().uint(e.call.xid).uint(REPLY).uint(MSG_DENIED).uint(RPC_MISMATCH)
                     .uint(RPC_VERSION).uint(RPC_VERSION))
    except XdrError:
        return None
    program = programs.get(call.prog)
    if program is None:
        return _accepted(call.xid, PROG_UNAVAIL)
    if not program.low <= call.vers <= program.high:
        return _accepted(call.xid, PROG_MISMATCH, bytes(XdrWriter().uint(program.low).uint(program.high)))
    if call.proc == 0:
        return _accepted(call.xid, SUCCESS)
    procedure = program.procedures.get(call.proc)
    if procedure is None:
        return _accepted(call.xid, PROC_UNAVAIL)
    try:
        result = procedure(args)
    except XdrError:
        return _accepted(call.xid, GARBAGE_ARGS)
    return _accepted(call.xid, SUCCESS, result)


def serve_connection(conn: socket.socket, programs: Mapping[int, Program], max_record: int,
                     watch: Connection | None = None) -> None:
    """Answer the calls of one TCP connection in order until the peer goes; a record over
    ``max_record`` bytes ends the connection (``RecordTooLarge``, a protocol violation the
    listener reports). ``watch``: the connection's record with its listener, whose clock
    says when the client was heard and while a call of its runs (a device_read waiting)."""
    while True:
        try:
            await_message(conn)
            if watch is not None:
                watch.clock.heard()
            record = read_record(conn, max_record)
        except RecordTooLarge:
            raise
        except ConnectionError:
            return  # the peer closed, between calls or within one
        if watch is None:
            reply = answer(record, programs)
        else:
            with watch.clock.working():
                reply = answer(record, programs)
        if reply is not None:
            write_record(conn, reply)


# ---- a client, for registering with another portmapper and for tests ----------------------

class RpcClient:
    """Calls one program over one TCP connection, in turn (record marking, AUTH_NONE)."""

    _xids = itertools.count(1)
    _xid_lock = threading.Lock()

    def __init__(self, host: str, port: int, prog: int, vers: int, *, timeout_s: float = 5.0,
                 max_reply: int = 1 << 24) -> None:
        self.prog, self.vers, self._max = prog, vers, max_reply
        self._sock = socket.create_connection((host, port), timeout=timeout_s)

    def call(self, proc: int, args: bytes = b"") -> XdrReader:
        """The result of ``proc`` (a reader at its first item); ``RpcError`` when the server
        did not run it."""
        with self._xid_lock:
            xid = next(self._xids) & 0xFFFF_FFFF
        header = (XdrWriter().uint(xid).uint(CALL).uint(RPC_VERSION).uint(self.prog).uint(self.vers)
                  .uint(proc).uint(AUTH_NONE).opaque(b"").uint(AUTH_NONE).opaque(b""))
        write_record(self._sock, bytes(header) + args)
        r = XdrReader(read_record(self._sock, self._max))
        if r.uint() != xid or r.uint() != REPLY:
            raise RpcError("reply does not answer the call (xid or type)")
        if r.uint() == MSG_DENIED:
            raise RpcError(f"call denied (reject status {r.uint()})")
        r.uint()
        r.opaque(MAX_AUTH_BYTES)
        status = r.uint()
        if status != SUCCESS:
            names = {PROG_UNAVAIL: "PROG_UNAVAIL", PROG_MISMATCH: "PROG_MISMATCH",
                     PROC_UNAVAIL: "PROC_UNAVAIL", GARBAGE_ARGS: "GARBAGE_ARGS", SYSTEM_ERR: "SYSTEM_ERR"}
            raise RpcError(f"program {self.prog} version {self.vers} procedure {proc}: "
                           f"{names.get(status, status)}")
        return r

    def close(self) -> None:
        self._sock.close()
