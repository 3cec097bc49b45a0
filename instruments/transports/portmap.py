"""The portmapper (RFC 1833, program 100000 version 2): where a VISA client asks, on port 111,
which TCP port a VXI-11 instrument's core channel listens on.

``PortMapper`` is one, over TCP and UDP on one port (111 for clients to find it; tests may
give 0): NULL, SET, UNSET, GETPORT and DUMP; CALLIT (an indirect call) is not offered
(PROC_UNAVAIL). ``announce`` makes a program findable: it registers with the portmapper that
already answers on port 111 (a system rpcbind, or another process's), or, where none answers
and the caller allows it, starts one here; its ``how`` says which."""
from __future__ import annotations

import contextlib
import socket
import threading
from dataclasses import dataclass

from instruments.errors import InstrumentError
from instruments.transports import oncrpc
from instruments.transports.tcp import TcpService

PMAP_PROG, PMAP_VERS, PMAP_PORT = 100000, 2, 111
PMAPPROC_SET, PMAPPROC_UNSET, PMAPPROC_GETPORT, PMAPPROC_DUMP = 1, 2, 3, 4
IPPROTO_TCP, IPPROTO_UDP = 6, 17
MAX_RECORD = 4096
"""The largest call a portmapper takes: its arguments are four integers."""


@dataclass(frozen=True)
class PortMapping:
    """One registration: program, version, protocol (6 TCP, 17 UDP) and port."""

    prog: int
    vers: int
    prot: int
    port: int

    def packed(self) -> bytes:
        return bytes(oncrpc.XdrWriter().uint(self.prog).uint(self.vers).uint(self.prot).uint(self.port))

    @classmethod
    def unpacked(cls, r: oncrpc.XdrReader) -> PortMapping:
        m = cls(r.uint(), r.uint(), r.uint(), r.uint())
        r.done()
        return m


class PortMapper:
    """A portmapper on (host, port) over TCP and UDP. ``start()`` serves; ``close()`` stops."""

    def __init__(self, host: str = "127.0.0.1", port: int = PMAP_PORT) -> None:
        self._table: dict[tuple[int, int, int], int] = {}
        self._guard = threading.Lock()
        program = oncrpc.Program(PMAP_PROG, PMAP_VERS, PMAP_VERS, {
            PMAPPROC_SET: self._set, PMAPPROC_UNSET: self._unset,
            PMAPPROC_GETPORT: self._getport, PMAPPROC_DUMP: self._dump})
        self._programs = {PMAP_PROG: program}
        self._tcp = TcpService(self._serve_tcp, host, port, name="portmap-tcp")
        self.host, self.port = self._tcp.host, self._tcp.port
        try:
            self._udp = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
            self._udp.bind((host, self.port))
        except OSError:
            self._tcp.close()
            raise
        self._udp.settimeout(0.2)
        self._stop = threading.Event()
        self._udp_thread = threading.Thread(target=self._serve_udp, name="portmap-udp", daemon=True)

    def start(self) -> PortMapper:
        self._tcp.start()
        self._udp_thread.start()
        return self

    def mappings(self) -> list[PortMapping]:
        """What is registered now."""
        with self._guard:
            return [PortMapping(p, v, t, port) for (p, v, t), port in self._table.items()]

    def register(self, m: PortMapping) -> bool:
        """Map (prog, vers, prot) to its port; False when already mapped (RFC 1833: SET
        refuses a triple that is mapped, UNSET it first)."""
        with self._guard:
            taken = (m.prog, m.vers, m.prot) in self._table
            if not taken:
                self._table[(m.prog, m.vers, m.prot)] = m.port
            return not taken

    def _set(self, r: oncrpc.XdrReader) -> bytes:
        return bytes(oncrpc.XdrWriter().bool(self.register(PortMapping.unpacked(r))))

    def _unset(self, r: oncrpc.XdrReader) -> bytes:
        m = PortMapping.unpacked(r)  # UNSET ignores prot and port: every protocol of (prog, vers)
        with self._guard:
            keys = [k for k in self._table if k[:2] == (m.prog, m.vers)]
            for k in keys:
                del self._table[k]
        return bytes(oncrpc.XdrWriter().bool(bool(keys)))

    def _getport(self, r: oncrpc.XdrReader) -> bytes:
        m = PortMapping.unpacked(r)
        with self._guard:
            port = self._table.get((m.prog, m.vers, m.prot), 0)
        return bytes(oncrpc.XdrWriter().uint(port))

    def _dump(self, r: oncrpc.XdrReader) -> bytes:
        r.done()
        out = oncrpc.XdrWriter()
        for m in self.mappings():  # a linked list: "value follows" before each entry
            out.bool(True).raw(m.packed())
        return bytes(out.bool(False))

    def _serve_tcp(self, conn: socket.socket, peer: str) -> None:
        oncrpc.serve_connection(conn, self._programs, MAX_RECORD)

    def _serve_udp(self) -> None:
        while not self._stop.is_set():
            try:
                datagram, addr = self._udp.recvfrom(MAX_RECORD)
            except TimeoutError:
                continue
            except OSError:
                return
            reply = oncrpc.answer(datagram, self._programs)
            if reply is not None:
                with contextlib.suppress(OSError):  # the asker is gone; a UDP caller retries
                    self._udp.sendto(reply, addr)

    def close(self) -> None:
        self._stop.set()
        self._tcp.close()
        self._udp.close()
        self._udp_thread.join(timeout=2.0)


class Announcement:
    """A program made findable through the portmapper on ``port``; ``close()`` unregisters it,
    or, when this announcement started that portmapper, stops it (and with it whatever other
    processes registered there meanwhile: the port is this process's until it ends)."""

    def __init__(self, mappings: list[PortMapping], host: str, port: int, started: PortMapper | None) -> None:
        self.mappings, self._host, self.port, self._started = mappings, host, port, started
        self.how = (f"started a portmapper on port {port}" if started else
                    f"registered with the portmapper already answering on port {port}")

    def close(self) -> None:
        if self._started is not None:
            self._started.close()
            self._started = None
            return
        with contextlib.suppress(OSError):  # that portmapper is gone, and the registration with it
            _call_each(self._host, self.port, PMAPPROC_UNSET, self.mappings)


def _call_each(host: str, port: int, proc: int, mappings: list[PortMapping]) -> list[bool]:
    client = oncrpc.RpcClient(host, port, PMAP_PROG, PMAP_VERS, timeout_s=2.0)
    try:
        return [client.call(proc, m.packed()).bool() for m in mappings]
    finally:
        client.close()


def getport(host: str, prog: int, vers: int, *, port: int = PMAP_PORT) -> int:
    """The TCP port the portmapper at (host, port) gives (prog, vers); 0 when unregistered."""
    client = oncrpc.RpcClient(host, port, PMAP_PROG, PMAP_VERS, timeout_s=2.0)
    try:
        return client.call(PMAPPROC_GETPORT, PortMapping(prog, vers, IPPROTO_TCP, 0).packed()).uint()
    finally:
        client.close()


def announce(programs: list[tuple[int, int, int]], host: str = "127.0.0.1", *,
             port: int = PMAP_PORT, start: bool = True) -> Announcement:
    """Register each (prog, vers, tcp port) with the portmapper answering on (host, port); when
    none answers and ``start`` is set, start one there first. Raises ``InstrumentError`` (one
    line) when neither is possible."""
    mappings = [PortMapping(p, v, IPPROTO_TCP, tcp_port) for p, v, tcp_port in programs]
    try:
        accepted = _call_each(host, port, PMAPPROC_SET, mappings)
    except (OSError, oncrpc.XdrError) as e:
        if not start:
            raise InstrumentError(f"portmapper on {host}:{port}: {e}; allowed: a running portmapper "
                                  f"(or let this process start one)") from None
    else:
        if not all(accepted):  # mapped already (a server gone, or another one): this one wins
            _call_each(host, port, PMAPPROC_UNSET, mappings)
            accepted = _call_each(host, port, PMAPPROC_SET, mappings)
        if not all(accepted):
            raise InstrumentError(f"portmapper on {host}:{port} refused to map {programs}")
        return Announcement(mappings, host, port, None)
    try:
        mapper = PortMapper(host, port).start()
    except OSError as e:
        raise InstrumentError(f"portmapper port = {port}: cannot be bound here ({e.strerror}) and no "
                              f"portmapper answers on it; clients must name the port "
                              f"(TCPIP::{host},PORT::INSTR)") from None
    for m in mappings:
        mapper.register(m)
    return Announcement(mappings, host, mapper.port, mapper)
