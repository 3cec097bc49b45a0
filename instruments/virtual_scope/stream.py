"""``CURVEStream?`` (4 Series MSO Programmer Manual, "CURVEStream?"): waveform records sent
one after another as they are acquired, formatted as ``CURVe?`` formats them (DATa,
WFMOutpre), until the controller takes the instrument out of streaming mode by a device
clear or by sending another command or query. The TDS2000's and MDO3000's manuals have no
such query: there it is an undefined header (-113).

Over the request/response transports the stream is served one record per read: the
session's ``next_reply`` gives the next acquisition's block, its shot asked for when the
transport can deliver it (VXI-11: the client's device_read; a raw socket and HiSLIP: once
the last block has left the connection, transports/stream.py), so that the client's reads
pace the acquisition (the manual: "the trigger rate is slowed to allow each waveform to be
sent sequentially") and nothing piles up where the client does not read. Each block is a
new shot at the next seed, the record ``rig shot`` gives at that seed with the scope's
settings, as a repeated single sequence and CURVe? would have it. A shot the rig refuses
answers CURVe?'s empty block, the reason in the queue, and ends the stream; one that does not
trigger in NORMal sends nothing: the stream waits for a trigger (acquisition.py), until the
client ends it. One stream at a time: a second client's is refused (-200)."""
from __future__ import annotations

from typing import Protocol, cast

from ..scpi.engine import LATER, Call
from ..scpi.status import ScpiError
from .waveform_commands import curve_answer


class Streaming(Protocol):
    """A client's session as a stream knows it (instrument.ScopeSession): its stream on."""

    stream: CurveStream | None


class CurveStream:
    """One client's stream of curves (``session``'s), under the scope's condition."""

    def __init__(self, scope, session, found) -> None:
        self.scope, self.session, self.found = scope, session, found
        self.asked: int | None = None  # acq.finished when the next block's record was asked for
        self.ended = False
        scope.stream = self
        scope.acq.stream(True)

    def next_block(self, wait_s: float) -> bytes | None:
        """The next block (holding the scope's condition, released while waiting): the
        next acquisition's curve and its newline, b"" when it is not in within ``wait_s``
        (it comes on a later call), None once the stream ended."""
        acq, cond = self.scope.acq, self.scope.cond
        if self.ended or acq.closed:
            return None
        if self.asked is None:
            self.asked = acq.finished
            acq.want()
        asked = self.asked
        if not cond.wait_for(lambda: self.ended or acq.closed or acq.finished > asked, timeout=wait_s):
            return b""
        if self.ended or acq.closed:
            return None
        self.asked = None
        body, whole = curve_answer(self.scope, "CURVEStream?")
        if not whole:
            self.end()
        return self.scope.engine.reply(body, self.found) + b"\n"

    def end(self) -> None:
        """Out of streaming mode: no further record is asked for."""
        if not self.ended:
            self.ended = True
            if self.scope.stream is self:
                self.scope.stream = None
                self.scope.acq.stream(False)
            self.scope.cond.notify_all()


def register(tree, scope) -> None:
    """``CURVEStream?`` on a model whose manual has it (Personality.streams)."""
    if not scope.personality.streams:
        return

    def curvestream(c: Call):
        c.only(0)
        session = cast(Streaming, c.context)
        other = scope.stream
        if other is not None and other.session is not session:
            raise ScpiError(-200, f"{c.header}: another client streams curves now; one stream at a time")
        if other is not None:  # asked twice in one message: one stream
            other.end()
        session.stream = CurveStream(scope, session, tree.find(("CURVESTREAM",)))
        return LATER

    tree.add("CURVEStream", read=curvestream)
