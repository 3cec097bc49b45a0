"""The loops of a HiSLIP session's two channels (IVI-6.1, synchronized mode).

Synchronous channel: Data parts are gathered into one program message up to DataEnd (at most
``max_message`` bytes kept); the instrument's reply goes back as Data parts and a DataEnd no
larger than the client's maximum message size, carrying the id of the message it answers (a
streamed reply, CURVEStream?, each of its responses so, until the next message or clear).
A client that starts a new message without having taken the last reply (RMT-delivered clear)
interrupts it: Interrupted and AsyncInterrupted are sent. AsyncDeviceClear clears the
instrument session at once; from then to DeviceClearComplete whatever arrives on the
synchronous channel, and the reply of a message the clear caught in the instrument, is dropped.

Asynchronous channel: one reply to each request (AsyncLock, AsyncLockInfo, AsyncStatusQuery,
AsyncDeviceClear, AsyncMaximumMessageSize, AsyncRemoteLocalControl). A lock request waits at
most its timeout (milliseconds); an empty lock string asks for the exclusive lock."""
from __future__ import annotations

import socket
import struct

from instruments.transports.hislip_codec import (
    MAV,
    Error,
    Fatal,
    Header,
    Kind,
    LockReply,
    ProtocolError,
    discard,
    read_header,
)
from instruments.transports.hislip_link import WAIT_SLICE_S, Link
from instruments.transports.stream import pump_if_streaming
from instruments.transports.tcp import recv_exact

MAX_LOCK_STRING = 256
"""The longest shared-lock string taken (bytes)."""


class _Message:
    """The program message being gathered from Data parts."""

    def __init__(self) -> None:
        self.parts = bytearray()
        self.size = 0
        self.started = False

    def reset(self) -> None:
        self.parts.clear()
        self.size, self.started = 0, False


def serve_sync(link: Link) -> None:
    """The synchronous channel's loop, until the client goes or a FatalError."""
    _guarded(link, link.send_sync, _sync_loop)


def serve_async(link: Link) -> None:
    """The asynchronous channel's loop, until the client goes or a FatalError."""
    _guarded(link, link.send_async, _async_loop)


def _guarded(link: Link, send, loop) -> None:
    """Run a channel's loop; a header without the prologue ends the session with a FatalError."""
    try:
        loop(link)
    except ProtocolError as e:
        link.report(f"{e}: FatalError sent, the session ends")
        send(Kind.FATAL_ERROR, Fatal.POORLY_FORMED_HEADER, 0, str(e).encode())
        link.close("after the protocol violation")


def _sync_loop(link: Link) -> None:
    pending = _Message()
    while not link.closed.is_set():
        header = read_header(link.sync)
        link.clock.heard()
        if link.asynchronous is None:
            link.report(f"message type {header.kind} on the synchronous channel before AsyncInitialize: "
                        "FatalError sent, the session ends")
            link.send_sync(Kind.FATAL_ERROR, Fatal.NO_ASYNC_CHANNEL, 0,
                           b"message on the synchronous channel before AsyncInitialize")
            link.close("after the protocol violation")
            return
        if header.kind in (Kind.DATA, Kind.DATA_END):
            _data(link, header, pending)
        elif header.kind == Kind.TRIGGER:
            discard(link.sync, header.length)
            if not link.clearing.is_set():
                _start(link, header)
                with link.clock.working():
                    if link.wait_unlocked():
                        link.session.trigger()
        elif header.kind == Kind.DEVICE_CLEAR_COMPLETE:
            discard(link.sync, header.length)
            link.stop_pump()
            pending.reset()
            link.undelivered = False
            link.clearing.clear()
            link.send_sync(Kind.DEVICE_CLEAR_ACKNOWLEDGE, 0)  # feature: synchronized mode
        elif not _common(header, link.sync, link.send_sync, link.report):
            return


def _data(link: Link, header: Header, pending: _Message) -> None:
    """One Data or DataEnd part; at DataEnd the message goes to the instrument."""
    if link.clearing.is_set():
        discard(link.sync, header.length)
        return
    if not pending.started:
        _start(link, header)
        pending.started = True
    if header.length > link.max_message:
        discard(link.sync, header.length)
        link.report(f"a Data message of {header.length} bytes: allowed at most {link.max_message}; Error sent")
        link.send_sync(Kind.ERROR, Error.MESSAGE_TOO_LARGE, 0,
                       f"message length = {header.length}: allowed at most {link.max_message} bytes".encode())
    else:
        payload = recv_exact(link.sync, header.length)
        if pending.size + header.length <= link.max_message:
            pending.parts += payload
    pending.size += header.length
    if header.kind != Kind.DATA_END:
        return
    size, program = pending.size, bytes(pending.parts)
    pending.reset()
    if size > link.max_message:
        link.session.overflow(size)
        link.report(f"a program message of {size} bytes in Data parts: allowed at most {link.max_message}; refused")
        link.clock.done()
        return
    program = program[:-1] if program.endswith(b"\n") else program  # the terminator before END
    program = program[:-1] if program.endswith(b"\r") else program
    if not program:
        return
    link.stop_pump()  # a new message ends a streamed reply
    with link.clock.working():
        ran = link.wait_unlocked()
        reply = link.session.handle(program) if ran else b""
    if reply:
        link.send_reply(reply, header.parameter)
        link.clock.done()
    if ran:
        link.pump = pump_if_streaming(link.session, link.sync, lambda r: link.send_reply(r, header.parameter),
                                      lambda e: link.close("stalled: a streamed reply not taken"),
                                      f"hislip{link.id}-stream", link.clock)


def _start(link: Link, header: Header) -> None:
    """A new message (its first part, or a Trigger) arrived: was the last reply taken?"""
    if header.control & 1:  # RMT-delivered
        link.undelivered = False
    elif link.undelivered:
        link.undelivered = False
        link.send_sync(Kind.INTERRUPTED, 0, header.parameter)
        link.send_async(Kind.ASYNC_INTERRUPTED, 0, header.parameter)


def _async_loop(link: Link) -> None:
    conn = link.asynchronous
    assert conn is not None, "served once both channels are paired"
    while not link.closed.is_set():
        header = read_header(conn)
        link.clock.done()
        kind = header.kind
        if kind == Kind.ASYNC_MAXIMUM_MESSAGE_SIZE and header.length == 8:
            link.client_max = struct.unpack("!Q", recv_exact(conn, 8))[0]
            link.send_async(Kind.ASYNC_MAXIMUM_MESSAGE_SIZE_RESPONSE, 0, 0, struct.pack("!Q", link.max_message))
        elif kind == Kind.ASYNC_LOCK and header.control in (0, 1):
            with link.clock.working():  # a lock request may wait its timeout
                granted = _lock(link, header)
            link.send_async(Kind.ASYNC_LOCK_RESPONSE, granted)
        elif kind == Kind.ASYNC_LOCK_INFO:
            discard(conn, header.length)
            state = link.lock.state()
            link.send_async(Kind.ASYNC_LOCK_INFO_RESPONSE, int(state.exclusive), state.holders)
        elif kind == Kind.ASYNC_STATUS_QUERY:
            discard(conn, header.length)
            if header.control & 1:  # RMT-delivered: the last reply was taken whole
                link.undelivered = False
            status = link.session.status_byte() | (MAV if link.undelivered else 0)
            link.send_async(Kind.ASYNC_STATUS_RESPONSE, status & 0xFF)
        elif kind == Kind.ASYNC_DEVICE_CLEAR:
            discard(conn, header.length)
            link.clearing.set()
            link.session.device_clear()  # now, so that a query waiting in the instrument ends
            link.send_async(Kind.ASYNC_DEVICE_CLEAR_ACKNOWLEDGE, 0)  # feature: synchronized mode
        elif kind == Kind.ASYNC_REMOTE_LOCAL_CONTROL and header.control <= 6:
            discard(conn, header.length)  # no front panel to lock out: every request is granted
            link.send_async(Kind.ASYNC_REMOTE_LOCAL_RESPONSE)
        elif not _common(header, conn, link.send_async, link.report):
            return


def _lock(link: Link, header: Header) -> int:
    """An AsyncLock request (control 1) or release (control 0): the AsyncLockResponse code."""
    conn = link.asynchronous
    assert conn is not None, "served once both channels are paired"
    if header.control == 0:
        discard(conn, header.length)
        held, link.held = link.held, None
        if held is None or not link.lock.release(link):
            return LockReply.ERROR
        return LockReply.SUCCESS if held else LockReply.SUCCESS_SHARED
    if header.length > MAX_LOCK_STRING:
        discard(conn, header.length)
        return LockReply.ERROR
    name = recv_exact(conn, header.length).decode("latin-1")
    exclusive = not name
    left_s = header.parameter / 1000.0
    while True:
        step = min(left_s, WAIT_SLICE_S)
        if link.lock.acquire(link, exclusive=exclusive, shared_name=name, timeout_s=step):
            if link.closed.is_set():  # the server is closing: another's lock went with it
                link.lock.release(link)
                return LockReply.FAILURE
            link.held = bool(link.held) or exclusive
            return LockReply.SUCCESS
        left_s -= step
        if left_s <= 0 or link.closed.is_set():
            return LockReply.FAILURE


def _common(header: Header, conn: socket.socket, send, report) -> bool:
    """Messages either channel may get: errors from the client, unknown types. False when the
    session must end."""
    if header.kind == Kind.FATAL_ERROR:
        return False
    discard(conn, header.length)
    if header.kind == Kind.ERROR:
        return True  # the client's notice; nothing to undo
    if header.kind == Kind.ASYNC_MAXIMUM_MESSAGE_SIZE:
        code, text = Error.UNIDENTIFIED, f"AsyncMaximumMessageSize payload length = {header.length}: allowed 8"
    elif header.kind in (Kind.ASYNC_LOCK, Kind.ASYNC_REMOTE_LOCAL_CONTROL):
        code, text = (Error.UNRECOGNIZED_CONTROL_CODE,
                      f"control code = {header.control} of message type {header.kind}: not defined")
    elif header.kind >= 128:
        code, text = Error.UNRECOGNIZED_VENDOR_MESSAGE, f"vendor message type = {header.kind}: none served"
    else:
        code, text = Error.UNRECOGNIZED_MESSAGE_TYPE, f"message type = {header.kind}: not served on this channel"
    report(f"{text}; Error sent")
    send(Kind.ERROR, code, 0, text.encode())
    return True
