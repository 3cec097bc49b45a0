"""A TCP listener that gives each connection a thread, for every transport.

Loopback unless the caller names another address; at most ``max_clients`` connections at
once (one more is accepted and closed at once, so the client sees a clean refusal instead of
a hang); ``close()`` stops the listener and shuts every open connection down."""
from __future__ import annotations

import contextlib
import socket
import threading
from collections.abc import Callable

Handler = Callable[[socket.socket, str], None]
"""Serves one connection until the client goes; (its socket, "host:port" of the peer)."""


class TcpService:
    """Listens on (host, port) (port 0: a free one, see ``port``) and runs ``handler`` for
    each connection in a daemon thread."""

    def __init__(self, handler: Handler, host: str = "127.0.0.1", port: int = 0, *,
                 max_clients: int = 32, name: str = "tcp") -> None:
        self._handler = handler
        self._max = max_clients
        self.name = name
        self._listener = socket.create_server((host, port), reuse_port=False)
        self._listener.settimeout(0.2)
        self.host, self.port = self._listener.getsockname()[:2]
        self._clients: set[socket.socket] = set()
        self._guard = threading.Lock()
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._accept, name=f"{name}-accept", daemon=True)

    def start(self) -> TcpService:
        self._thread.start()
        return self

    @property
    def clients(self) -> int:
        """Connections open now."""
        with self._guard:
            return len(self._clients)

    def _accept(self) -> None:
        while not self._stop.is_set():
            try:
                conn, addr = self._listener.accept()
            except TimeoutError:
                continue
            except OSError:
                return
            with self._guard:
                full = len(self._clients) >= self._max
                if not full:
                    self._clients.add(conn)
            if full:
                conn.close()
                continue
            conn.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            peer = f"{addr[0]}:{addr[1]}"
            threading.Thread(target=self._serve, args=(conn, peer), name=f"{self.name}-{peer}",
                             daemon=True).start()

    def _serve(self, conn: socket.socket, peer: str) -> None:
        try:
            self._handler(conn, peer)
        except OSError:
            pass  # the client went away mid-message: nothing of the instrument's is lost
        finally:
            with self._guard:
                self._clients.discard(conn)
            conn.close()

    def close(self) -> None:
        """Stop listening and shut every connection down (their handlers then return)."""
        self._stop.set()
        self._listener.close()
        with self._guard:
            clients = list(self._clients)
        for conn in clients:
            with contextlib.suppress(OSError):
                conn.shutdown(socket.SHUT_RDWR)
        self._thread.join(timeout=2.0)


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
