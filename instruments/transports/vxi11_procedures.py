"""The VXI-11 procedures on an open link (VXI-11 rev. 1.0, B.6): device_write, device_read and
the out-of-band calls of the core channel, and device_abort of the abort channel; each reads
its XDR arguments and returns its packed response (``reply``).

A message is executed on a thread of its own (``Link.execute``), so that device_read,
device_readstb and the abort channel keep answering while a query waits on the instrument.
A streamed reply (CURVEStream?) is pulled: a device_read with nothing left to read takes the
stream's next response (``Link.streamed``), so each response is made when the client reads.
The interrupt channel (create_intr_chan, device_enable_srq) and device_docmd are not
offered: their arguments are read and error 8 (operation not supported) answered."""
from __future__ import annotations

import threading
from collections.abc import Callable

from instruments.transports import oncrpc
from instruments.transports.device import MessageInstrument
from instruments.transports.vxi11_codec import (
    CHANNEL_NOT_ESTABLISHED,
    CREATE_INTR_CHAN,
    DESTROY_INTR_CHAN,
    DEVICE_CLEAR,
    DEVICE_DOCMD,
    DEVICE_ENABLE_SRQ,
    DEVICE_LOCAL,
    DEVICE_LOCK,
    DEVICE_LOCKED,
    DEVICE_READ,
    DEVICE_READSTB,
    DEVICE_REMOTE,
    DEVICE_TRIGGER,
    DEVICE_UNLOCK,
    DEVICE_WRITE,
    FLAG_END,
    FLAG_TERMCHAR,
    FLAG_WAIT_LOCK,
    INVALID_LINK,
    MAV,
    NO_ERROR,
    NO_LOCK_HELD,
    OPERATION_NOT_SUPPORTED,
    PARAMETER_ERROR,
    REASON_CHR,
    REASON_END,
    REASON_REQCNT,
    reply,
)
from instruments.transports.vxi11_link import Link

MAX_READ_BYTES = 1 << 20
"""The most one device_read returns, whatever it requests (the client reads again)."""

Procedure = Callable[[oncrpc.XdrReader], bytes]


class LinkProcedures:
    """The procedures on the links of ``instrument`` that ``find`` returns by link id (None:
    no such link); a device_write takes at most ``max_recv_size`` bytes of data."""

    def __init__(self, instrument: MessageInstrument, find: Callable[[int], Link | None],
                 max_recv_size: int) -> None:
        self.instrument = instrument
        self.find = find
        self.max_recv_size = max_recv_size

    @property
    def core(self) -> dict[int, Procedure]:
        """The core channel's procedures on a link, by procedure number."""
        return {DEVICE_WRITE: self.device_write, DEVICE_READ: self.device_read,
                DEVICE_READSTB: self.device_readstb, DEVICE_TRIGGER: self.device_trigger,
                DEVICE_CLEAR: self.device_clear, DEVICE_REMOTE: self.device_remote_local,
                DEVICE_LOCAL: self.device_remote_local, DEVICE_LOCK: self.device_lock,
                DEVICE_UNLOCK: self.device_unlock, DEVICE_ENABLE_SRQ: self.device_enable_srq,
                DEVICE_DOCMD: self.device_docmd, CREATE_INTR_CHAN: self.create_intr_chan,
                DESTROY_INTR_CHAN: self.destroy_intr_chan}

    # ---- messages ------------------------------------------------------------------------

    def device_write(self, r: oncrpc.XdrReader) -> bytes:
        link_id, io_timeout_ms, lock_timeout_ms, flags = r.int(), r.uint(), r.uint(), r.int()
        data = r.opaque(self.max_recv_size + 1024)
        r.done()
        link = self.find(link_id)
        if link is None:
            return reply(INVALID_LINK, 0)
        if len(data) > self.max_recv_size:
            return reply(PARAMETER_ERROR, 0)
        error = link.lock_free(self.instrument.lock, flags, lock_timeout_ms)
        if error:
            return reply(error, 0)
        limit = self.instrument.max_message_bytes
        with link.cond:
            if flags & FLAG_END:  # the instrument takes one message at a time
                error = link.wait(lambda: not link.busy, io_timeout_ms)
                if error:
                    return reply(error, 0)
            link.message_size += len(data)
            if link.message_size <= limit:
                link.message += data
            else:
                link.message.clear()  # over size: counted, not kept
            if not flags & FLAG_END:
                return reply(NO_ERROR, len(data))
            size, message = link.message_size, bytes(link.message) if link.message_size <= limit else None
            link.message.clear()
            link.message_size = 0
            link.response, link.read_at = b"", 0  # a new message interrupts an unread response
            link.busy = True
            generation = link.generation
        threading.Thread(target=link.execute, args=(message, size, generation),
                         name=f"vxi11-link{link.id}", daemon=True).start()
        return reply(NO_ERROR, len(data))

    def device_read(self, r: oncrpc.XdrReader) -> bytes:
        link_id, request_size, io_timeout_ms, lock_timeout_ms = r.int(), r.uint(), r.uint(), r.uint()
        flags, term_char = r.int(), r.int()
        r.done()
        link = self.find(link_id)
        if link is None:
            return reply(INVALID_LINK, 0, data=b"")
        error = link.lock_free(self.instrument.lock, flags, lock_timeout_ms)
        if error:
            return reply(error, 0, data=b"")
        with link.cond:
            error = link.wait(link.streamed, io_timeout_ms)
            if error:
                return reply(error, 0, data=b"")
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
        return reply(NO_ERROR, reason, data=data)

    # ---- out of band ---------------------------------------------------------------------

    def generic(self, r: oncrpc.XdrReader) -> tuple[Link | None, int, int]:
        """(link, error, io_timeout ms) of the generic parameters: link, flags, lock and io
        timeouts; the error is 4 (no such link) or 11 (locked by another link) or 0."""
        link_id, flags, lock_timeout_ms, io_timeout_ms = r.int(), r.int(), r.uint(), r.uint()
        r.done()
        link = self.find(link_id)
        if link is None:
            return None, INVALID_LINK, io_timeout_ms
        return link, link.lock_free(self.instrument.lock, flags, lock_timeout_ms), io_timeout_ms

    def device_readstb(self, r: oncrpc.XdrReader) -> bytes:
        link, error, _ = self.generic(r)
        if error or link is None:  # no link: error is INVALID_LINK
            return reply(error, 0)
        with link.cond:
            unread = link.unread()
        return reply(NO_ERROR, link.session.status_byte() & ~MAV | (MAV if unread else 0))

    def device_trigger(self, r: oncrpc.XdrReader) -> bytes:
        link, error, io_timeout_ms = self.generic(r)
        if error or link is None:  # no link: error is INVALID_LINK
            return reply(error)
        with link.cond:  # in order: after the message before it
            error = link.wait(lambda: not link.busy, io_timeout_ms)
        if not error:
            link.session.trigger()
        return reply(error)

    def device_clear(self, r: oncrpc.XdrReader) -> bytes:
        link, error, _ = self.generic(r)
        if error or link is None:  # no link: error is INVALID_LINK
            return reply(error)
        with link.cond:
            link.generation += 1
            link.message.clear()
            link.message_size = 0
            link.response, link.read_at = b"", 0
        link.session.device_clear()
        return reply(NO_ERROR)

    def device_remote_local(self, r: oncrpc.XdrReader) -> bytes:
        """device_remote / device_local: a network instrument has no front-panel lockout to
        switch; answered (after the link and lock checks) with no change."""
        return reply(self.generic(r)[1])

    def device_lock(self, r: oncrpc.XdrReader) -> bytes:
        link_id, flags, lock_timeout_ms = r.int(), r.int(), r.uint()
        r.done()
        link = self.find(link_id)
        if link is None:
            return reply(INVALID_LINK)
        wait_s = lock_timeout_ms / 1000 if flags & FLAG_WAIT_LOCK else 0.0
        return reply(NO_ERROR if self.instrument.lock.acquire(link, timeout_s=wait_s) else DEVICE_LOCKED)

    def device_unlock(self, r: oncrpc.XdrReader) -> bytes:
        link_id = r.int()
        r.done()
        link = self.find(link_id)
        if link is None:
            return reply(INVALID_LINK)
        return reply(NO_ERROR if self.instrument.lock.release(link) else NO_LOCK_HELD)

    def device_abort(self, r: oncrpc.XdrReader) -> bytes:
        """The abort channel: ends the link's call in progress (a read or write waiting)
        with error 23; a message already executing runs to its end."""
        link = self.find(r.int())
        r.done()
        if link is None:
            return reply(INVALID_LINK)
        with link.cond:
            if link.in_call:
                link.aborted = True
                link.cond.notify_all()
        return reply(NO_ERROR)

    # ---- not offered: the interrupt channel and docmd ------------------------------------

    def device_enable_srq(self, r: oncrpc.XdrReader) -> bytes:
        r.int(), r.bool(), r.opaque(40)
        r.done()
        return reply(OPERATION_NOT_SUPPORTED)

    def device_docmd(self, r: oncrpc.XdrReader) -> bytes:
        r.int(), r.int(), r.uint(), r.uint(), r.int(), r.bool(), r.int(), r.opaque(self.max_recv_size)
        r.done()
        return reply(OPERATION_NOT_SUPPORTED, data=b"")

    @staticmethod
    def create_intr_chan(r: oncrpc.XdrReader) -> bytes:
        r.uint(), r.uint(), r.uint(), r.uint(), r.int()
        r.done()
        return reply(OPERATION_NOT_SUPPORTED)

    @staticmethod
    def destroy_intr_chan(r: oncrpc.XdrReader) -> bytes:
        r.done()
        return reply(CHANNEL_NOT_ESTABLISHED)
