"""VXI-11's numbers (VXI-11 rev. 1.0, appendix B): the core and abort channels' program and
procedure numbers, the error codes, the flags of a call and the reasons a read stops; and
``reply``, which packs a procedure's response as XDR."""
from __future__ import annotations

from instruments.transports import oncrpc

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


def reply(*fields: int, data: bytes | None = None) -> bytes:
    """Packs a response: its integer fields (error first), then the opaque data if any."""
    w = oncrpc.XdrWriter()
    for f in fields:
        w.int(f)
    if data is not None:
        w.opaque(data)
    return bytes(w)
