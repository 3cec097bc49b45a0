"""A raw-socket client's one query, as the wire tests send it: the reply line it gets."""
from __future__ import annotations

import socket


def query(s: socket.socket, message: bytes) -> bytes:
    """Send ``message`` on ``s`` and read up to the reply's newline (b"" if the server closes)."""
    s.sendall(message)
    reply = b""
    while not reply.endswith(b"\n"):
        chunk = s.recv(4096)
        if not chunk:
            break
        reply += chunk
    return reply
