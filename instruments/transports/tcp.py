"""A TCP listener that gives each connection a thread, for every transport.

Loopback unless the caller names another address (IPv4 or IPv6; ``::`` listens on both
families). The address and port are taken when the service is made (so a bad one is
refused before anything costly), connections only once it is started. Each connection is
watched as ``wire.py`` lays out (``Limits``): at most ``max_clients`` at once and a share of
them per address, idle and half-open connections closed, a quiet one evicted when a
newcomer needs its slot; a newcomer with no slot is accepted and closed at once, so the
client sees a clean refusal instead of a hang. Every connection, end, refusal and protocol
violation is told to ``on_event``. ``close()`` stops the listener and shuts every open
connection down."""
from __future__ import annotations

import contextlib
import select
import socket
import threading
import time
from collections.abc import Callable
from dataclasses import replace

from instruments.transports.addresses import is_wildcard, peer_text, resolve
from instruments.transports.wire import Connection, ConnectionEvent, EventKind, EventSink, Limits

Handler = Callable[[socket.socket, str], None]
"""Serves one connection until the client goes; (its socket, "host:port" of the peer)."""
SEND_CHUNK = 1 << 18
"""A reply goes out in pieces this large: each must leave within the stall timeout."""


class ProtocolViolation(ConnectionError):
    """The client broke its protocol's framing so that the connection cannot go on; the
    listener reports it (``EventKind.VIOLATION``) and closes the connection."""


class TcpService:
    """Listens on (host, port) (port 0: a free one, see ``port``) and runs ``handler`` for
    each connection in a daemon thread. ``awaiting``: the opening message a connection must
    complete within the half-open timeout (None: open at once); the handler says it is done
    by clearing ``connection(sock).awaiting``. Raises ``OSError`` when (host, port) cannot
    be taken."""

    def __init__(self, handler: Handler, host: str = "127.0.0.1", port: int = 0, *,
                 max_clients: int | None = None, name: str = "tcp", limits: Limits | None = None,
                 on_event: EventSink | None = None, awaiting: str | None = None) -> None:
        self._handler = handler
        limits = limits or Limits()
        self.limits = limits if max_clients is None else replace(limits, max_clients=max_clients,
                                                                   per_address=None)
        self.name = name
        self._on_event = on_event
        self._awaiting = awaiting
        family, address = resolve(host)
        self._listener = socket.socket(family, socket.SOCK_STREAM)
        try:
            self._listener.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
            if family == socket.AF_INET6:  # '::' takes IPv4 clients too; another v6 address only its own
                self._listener.setsockopt(socket.IPPROTO_IPV6, socket.IPV6_V6ONLY, 0 if is_wildcard(address) else 1)
            self._listener.bind((address, port))
        except OSError:
            self._listener.close()
            raise
        self._listener.settimeout(0.2)
        self.host, self.port = self._listener.getsockname()[:2]
        self._clients: dict[socket.socket, Connection] = {}
        self._serving: set[threading.Thread] = set()  # the connections' handlers, until each has said its end
        self._guard = threading.Lock()
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._accept, name=f"{name}-accept", daemon=True)
        self._watch = threading.Thread(target=self._watchdog, name=f"{name}-watch", daemon=True)

    def start(self) -> TcpService:
        self._listener.listen(128)
        self._thread.start()
        self._watch.start()
        return self

    @property
    def clients(self) -> int:
        """Connections open now."""
        with self._guard:
            return len(self._clients)

    def connection(self, sock: socket.socket) -> Connection:
        """The watched connection of ``sock`` (a handler's own socket)."""
        with self._guard:
            found = self._clients.get(sock)
        return found if found is not None else Connection(sock, "?", "?")  # evicted meanwhile: unwatched

    def report(self, kind: EventKind, peer: str, detail: str = "") -> None:
        """Tell the owner of an event of this service's (a handler's refusals and violations)."""
        if self._on_event is not None:
            with contextlib.suppress(Exception):  # a failing log must not end a connection
                self._on_event(ConnectionEvent(kind, self.name, peer, detail))

    def _accept(self) -> None:
        while not self._stop.is_set():
            try:
                sock, addr = self._listener.accept()
            except TimeoutError:
                continue
            except OSError:
                return
            c = Connection(sock, peer_text(addr), str(addr[0]), self._awaiting)
            with self._guard:
                refusal = self._admit(c)
                if refusal is None:
                    self._clients[sock] = c
            if refusal is not None:
                sock.close()
                self.report(EventKind.REFUSED, c.peer, refusal)
                continue
            sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            self.report(EventKind.CONNECTED, c.peer)
            handler = threading.Thread(target=self._serve, args=(c,), name=f"{self.name}-{c.peer}", daemon=True)
            with self._guard:
                self._serving.add(handler)
            handler.start()

    def _admit(self, c: Connection) -> str | None:
        """Make room for ``c`` (holding the guard): None when it may come in, evicting a quiet
        connection where its address's share or every slot is taken; else why it is refused."""
        limits, now = self.limits, time.monotonic()
        if not c.loopback:
            same = [x for x in self._clients.values() if x.address == c.address]
            if len(same) >= limits.share:
                if self._evict(same, now, f"its address ({c.address}) holds its share of {limits.share} "
                                          f"connections and {c.peer} came"):
                    return None
                return (f"address {c.address} holds {len(same)} connections, none quiet for {limits.grace_s:g} s: "
                        f"allowed {limits.share} an address (of {limits.max_clients})")
        if len(self._clients) < limits.max_clients:
            return None
        counts: dict[str, int] = {}
        for x in self._clients.values():
            counts[x.address] = counts.get(x.address, 0) + 1
        if self._evict(list(self._clients.values()), now, f"all {limits.max_clients} connections were taken "
                                                          f"and {c.peer} came", lambda x: counts[x.address]):
            return None
        return f"all {limits.max_clients} connections are taken, none quiet for {limits.grace_s:g} s"

    def _evict(self, candidates: list[Connection], now: float, why: str,
               weight: Callable[[Connection], int] = lambda x: 0) -> bool:
        """Close the quietest of ``candidates`` quiet for at least the grace, among those of the
        greatest ``weight`` (the address holding the most connections pays first), holding the
        guard; False when none is quiet for as long."""
        eligible = [(weight(x), quiet, x) for x in candidates
                    if (quiet := x.clock.quiet_s(now)) is not None and quiet >= self.limits.grace_s]
        if not eligible:
            return False
        _, quiet, victim = max(eligible, key=lambda e: (e[0], e[1]))
        del self._clients[victim.sock]
        victim.close(f"evicted: no message for {quiet:.1f} s, and {why}")
        return True

    def _watchdog(self) -> None:
        limits = self.limits
        while not self._stop.wait(limits.tick_s()):
            now = time.monotonic()
            with self._guard:
                watched = list(self._clients.values())
            for c in watched:
                idle = c.clock.idle_s(now)
                if c.awaiting is not None and now - c.opened > limits.half_open_timeout_s:
                    c.close(f"half-open: no {c.awaiting} within {limits.half_open_timeout_s:g} s")
                elif limits.idle_timeout_s and idle is not None and idle > limits.idle_timeout_s:
                    c.close(f"idle: nothing from the client for {limits.idle_timeout_s:g} s")

    def _serve(self, c: Connection) -> None:
        why = "closed by the client"
        try:
            self._handler(c.sock, c.peer)
        except ProtocolViolation as e:
            self.report(EventKind.VIOLATION, c.peer, str(e))
            why = "after the protocol violation"
        except TimeoutError:
            if c.reason is None:
                self.report(EventKind.VIOLATION, c.peer, f"stalled: a message (or a reply) made no progress "
                                                         f"for {self.limits.stall_timeout_s:g} s")
                why = "stalled"
        except OSError:
            pass  # the client went away mid-message: nothing of the instrument's is lost
        finally:
            with self._guard:
                self._clients.pop(c.sock, None)
            c.sock.close()
            self.report(EventKind.DISCONNECTED, c.peer, c.reason or why)
            with self._guard:
                self._serving.discard(threading.current_thread())

    def close(self) -> None:
        """Stop listening and shut every connection down; return once each handler has said
        its end (the log whole), or after 2 s for those held inside the instrument. A
        connection the kernel completed that no accept() has taken yet is taken here, said
        and ended (the client had connected: shutting the listener would drop it unsaid)."""
        self._stop.set()
        self._end_waiting()
        with contextlib.suppress(OSError):  # wakes an accept() that waits, instead of its 0.2 s poll
            self._listener.shutdown(socket.SHUT_RDWR)
        self._listener.close()
        if self._thread.is_alive():  # what it took meanwhile is among the clients once it has ended
            self._thread.join(timeout=2.0)
        with self._guard:
            clients = list(self._clients.values())
        for c in clients:
            c.close("the server is closing")
        if self._watch.is_alive():
            self._watch.join(timeout=2.0)
        with self._guard:
            serving = list(self._serving)
        deadline = time.monotonic() + 2.0
        for thread in serving:
            thread.join(timeout=max(0.0, deadline - time.monotonic()))

    def _end_waiting(self) -> None:
        """Take each connection the kernel has queued for the listener (the accept thread
        may take some of them too, and serves those), say it and end it: "the server is
        closing"."""
        while True:
            try:
                if not select.select([self._listener], [], [], 0)[0]:
                    return
                sock, addr = self._listener.accept()
            except (OSError, ValueError):  # the accept thread took it first (a timeout), or the listener is closed
                return
            peer = peer_text(addr)
            sock.close()
            self.report(EventKind.CONNECTED, peer)
            self.report(EventKind.DISCONNECTED, peer, "the server is closing")


def recv_exact(conn: socket.socket, n: int) -> bytes:
    """Exactly ``n`` bytes from ``conn``; raises ConnectionError when the peer closes first."""
    chunks, left = [], n
    while left:
        chunk = conn.recv(min(left, 1 << 20))
        if not chunk:
            raise ConnectionError("peer closed the connection")
        chunks.append(chunk)
        left -= len(chunk)
    return b"".join(chunks)


def await_message(conn: socket.socket) -> None:
    """Wait, as long as it takes, for the first byte of the client's next message (left
    unread); ConnectionError when the client closes first (or its listener shut it). A
    socket timeout (the stall limit of a message begun) does not end this wait."""
    while True:
        try:
            if not conn.recv(1, socket.MSG_PEEK):
                raise ConnectionError("peer closed the connection")
            return
        except TimeoutError:
            continue


def send_all(conn: socket.socket, data: bytes) -> None:
    """``conn.sendall(data)`` in pieces of SEND_CHUNK, so that a socket timeout bounds a
    pause of the client's, not the time a long reply takes."""
    view = memoryview(data)
    for start in range(0, len(view), SEND_CHUNK):
        conn.sendall(view[start:start + SEND_CHUNK])
