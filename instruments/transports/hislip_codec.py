"""The HiSLIP wire format (IVI-6.1): the 16-byte message header and the message table.

Every message is ``"HS"``, a message type (byte), a control code (byte), a message parameter
(32 bits) and a payload length (64 bits), big-endian, then the payload."""
from __future__ import annotations

import socket
import struct
from dataclasses import dataclass
from enum import IntEnum

from instruments.transports.tcp import await_message, recv_exact

PROLOGUE = b"HS"
HEADER = struct.Struct("!2sBBIQ")
VERSION_1_0, VERSION_2_0 = 0x0100, 0x0200
"""Protocol versions as the Initialize messages carry them (major byte, minor byte)."""
ANY_MESSAGE_ID = 0xFFFF_FFFF
"""The message id a server gives a response that answers no message in particular."""
MAV = 0x10
"""Message available: the status byte's bit a server sets while a response is undelivered."""


class Kind(IntEnum):
    """The message types of IVI-6.1 (table 4), with the channel each belongs to."""

    INITIALIZE = 0                    # sync, client: version, vendor; payload sub-address
    INITIALIZE_RESPONSE = 1           # sync, server: overlap mode; version, session id
    FATAL_ERROR = 2                   # either channel, either side; the connection ends
    ERROR = 3                         # either channel, either side
    ASYNC_LOCK = 4                    # async, client: request (1, timeout ms) or release (0)
    ASYNC_LOCK_RESPONSE = 5
    DATA = 6                          # sync: a part of a message (RMT-delivered; message id)
    DATA_END = 7                      # sync: the last part of a message (END)
    DEVICE_CLEAR_COMPLETE = 8         # sync, client: the clear is done on its side
    DEVICE_CLEAR_ACKNOWLEDGE = 9      # sync, server
    ASYNC_REMOTE_LOCAL_CONTROL = 10
    ASYNC_REMOTE_LOCAL_RESPONSE = 11
    TRIGGER = 12                      # sync, client: group execute trigger
    INTERRUPTED = 13                  # sync, server: a response was abandoned
    ASYNC_INTERRUPTED = 14            # async, server
    ASYNC_MAXIMUM_MESSAGE_SIZE = 15   # async, client: payload its maximum (64 bits)
    ASYNC_MAXIMUM_MESSAGE_SIZE_RESPONSE = 16
    ASYNC_INITIALIZE = 17             # async, client: the session id
    ASYNC_INITIALIZE_RESPONSE = 18    # async, server: the server's vendor id
    ASYNC_DEVICE_CLEAR = 19
    ASYNC_SERVICE_REQUEST = 20
    ASYNC_STATUS_QUERY = 21           # async, client: RMT-delivered; message id
    ASYNC_STATUS_RESPONSE = 22        # async, server: the status byte in the control code
    ASYNC_DEVICE_CLEAR_ACKNOWLEDGE = 23
    ASYNC_LOCK_INFO = 24
    ASYNC_LOCK_INFO_RESPONSE = 25     # control: exclusive lock granted; parameter: holders


class Fatal(IntEnum):
    """FatalError codes."""

    UNIDENTIFIED = 0
    POORLY_FORMED_HEADER = 1
    NO_ASYNC_CHANNEL = 2      # attempt to use the connection without both channels
    INVALID_INITIALIZATION = 3
    TOO_MANY_CLIENTS = 4


class Error(IntEnum):
    """Error (non-fatal) codes."""

    UNIDENTIFIED = 0
    UNRECOGNIZED_MESSAGE_TYPE = 1
    UNRECOGNIZED_CONTROL_CODE = 2
    UNRECOGNIZED_VENDOR_MESSAGE = 3
    MESSAGE_TOO_LARGE = 4


class LockReply(IntEnum):
    """AsyncLockResponse control codes."""

    FAILURE = 0
    SUCCESS = 1           # granted; or an exclusive lock released
    SUCCESS_SHARED = 2    # a shared lock released
    ERROR = 3             # a release of nothing held, a bad lock string


class ProtocolError(Exception):
    """The peer broke the framing (a header without the "HS" prologue): the connection ends."""


@dataclass(frozen=True)
class Header:
    """One message's header; its ``length`` payload bytes follow on the wire."""

    kind: int
    control: int
    parameter: int
    length: int


def message(kind: int, control: int = 0, parameter: int = 0, payload: bytes = b"") -> bytes:
    """One whole message, header and payload."""
    return HEADER.pack(PROLOGUE, kind, control, parameter, len(payload)) + payload


def read_header(conn: socket.socket) -> Header:
    """The next header on ``conn``, waited for as long as it takes (its bytes, once begun,
    within the socket's timeout); ProtocolError when it lacks the prologue."""
    await_message(conn)
    prologue, kind, control, parameter, length = HEADER.unpack(recv_exact(conn, HEADER.size))
    if prologue != PROLOGUE:
        raise ProtocolError(f"header prologue = {prologue!r}: allowed b'HS'")
    return Header(kind, control, parameter, length)


def discard(conn: socket.socket, length: int) -> None:
    """Read ``length`` payload bytes off ``conn`` and keep none of them."""
    sink = bytearray(min(length, 1 << 16))
    while length:
        got = conn.recv_into(sink, min(length, len(sink)))
        if not got:
            raise ConnectionError("peer closed the connection")
        length -= got
