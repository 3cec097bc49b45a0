"""What ``rig serve scope --log FILE`` records of the clients' commands: each command a
client sent that left an error in the scope's queue (a refused command, with its error in
SCPI form), at most MAX_LOGGED_REFUSALS a client; a client's curve stream (CURVEStream?):
its first record and its end, with how many records it gave and what ended it; the
server's log itself (one line per event, appended; silent without --log)."""
from __future__ import annotations

import itertools
import logging
from collections import deque
from pathlib import Path

from instruments.scpi.status import esr_bit
from instruments.transports.device import InstrumentLock, MessageInstrument, Session
from instruments.transports.wire import printable, quoted
from instruments.virtual_scope.instrument import VirtualScope
from rig.errors import invalid

_LOGS = itertools.count(1)
MAX_LOGGED_REFUSALS = 100
"""Refused commands logged per client; past them one line says the rest are not (a client
that sends junk cannot fill the disk through the log)."""


class Refusals:
    """Which errors each message left in the scope's queue, for the log: the queue as last
    seen, so that an event is told once, with the message that left it (a warning, such as a
    measurement's clipping, sets no error bit and is no refusal). An event posted
    outside any message (the acquisition's: a shot that failed or did not trigger) is not
    a refused command: the refused shot is logged where it is fired."""

    def __init__(self, scope: VirtualScope, log: logging.Logger) -> None:
        self.scope, self.log = scope, log
        self._seen: list = []
        self._shots: deque[str] = deque(maxlen=16)

    def shot_refused(self, reason: str) -> None:
        with self.scope.cond:
            self._shots.append(reason)

    def fresh(self) -> list:
        """The events posted since the last look (holding the scope's condition)."""
        events = list(self.scope.status.events)
        new = [e for e in events if not any(e is seen for seen in self._seen)]
        self._seen = events
        return [e for e in new if esr_bit(e.code) and not (e.code == -200 and (  # an error, not a warning
            e.detail.startswith("the shot of seed") or any(reason.startswith(e.detail) for reason in self._shots)))]


class LoggedInstrument:
    """The scope (or its RIG: port) as a transport serves it, each refused command logged."""

    def __init__(self, inner: MessageInstrument, refusals: Refusals, transport: str) -> None:
        self.inner, self.refusals, self.transport = inner, refusals, transport
        self.max_message_bytes: int = inner.max_message_bytes
        self.lock: InstrumentLock = inner.lock

    def open_session(self, peer: str) -> Session:
        return LoggedSession(self.inner.open_session(peer), self.refusals, f"{self.transport} {peer}")


class LoggedSession:
    """One client's session; a message that leaves events in the queue is logged with them,
    a curve stream when it gives its first record and when it ends."""

    def __init__(self, session: Session, refusals: Refusals, who: str) -> None:
        self.session, self.refusals, self.who = session, refusals, who
        self.logged = 0
        self.streamed = 0  # records of the stream on, handed to the transport

    def next_reply(self, wait_s: float) -> bytes | None:
        response = self.session.next_reply(wait_s)
        if response:
            if not self.streamed:
                self.refusals.log.info("curve stream to %s: its first record (CURVEStream?)", self.who)
            self.streamed += 1
        elif response is None and self.streamed:
            self._stream_ended("it ended: a shot gave no record, or the scope closed")
        return response

    def _stream_ended(self, how: str) -> None:
        if self.streamed:
            self.refusals.log.info("curve stream to %s ended after %d records: %s", self.who, self.streamed, how)
            self.streamed = 0

    def handle(self, message: bytes) -> bytes:
        self._stream_ended("the client's next message")
        with self.refusals.scope.cond:  # the scope's own: the message runs under it
            self.refusals.fresh()  # posted outside any message meanwhile: not this one's
            reply = self.session.handle(message)
            events = self.refusals.fresh()
        for event in events:
            self.logged += 1
            if self.logged <= MAX_LOGGED_REFUSALS:
                self.refusals.log.warning("refused command from %s: %s: %s", self.who, quoted(message),
                                          printable(event.text(scpi=True)))
            elif self.logged == MAX_LOGGED_REFUSALS + 1:
                self.refusals.log.warning("refused command from %s: more than %d; the rest are not logged",
                                          self.who, MAX_LOGGED_REFUSALS)
        return reply

    def device_clear(self) -> None:
        self._stream_ended("a device clear")
        self.session.device_clear()

    def trigger(self) -> None:
        self.session.trigger()

    def status_byte(self) -> int:
        return self.session.status_byte()

    def overflow(self, size: int) -> None:
        self.session.overflow(size)  # the transport logs it, as a protocol violation

    def close(self) -> None:
        self._stream_ended("the client went")
        self.session.close()


def server_log(path: Path | None) -> logging.Logger:
    """The server's log (``--log FILE``: appended, one line per event); silent without one
    (not even Python's last-resort handler on stderr). Each server has a log of its own."""
    log = logging.getLogger(f"rig.lab.serve.{next(_LOGS)}")
    log.propagate = False
    log.setLevel(logging.INFO)
    if path is None:
        log.addHandler(logging.NullHandler())
    else:
        try:
            handler = logging.FileHandler(path, encoding="utf-8")
        except OSError as e:
            raise invalid("--log", str(path), f"a file this process can write ({e.strerror})") from None
        handler.setFormatter(logging.Formatter("%(asctime)s %(levelname)s %(message)s"))
        log.addHandler(handler)
    return log
