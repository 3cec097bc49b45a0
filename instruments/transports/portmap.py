"""The portmapper (RFC 1833, program 100000 version 2): where a VISA client asks, on port 111,
which TCP port a VXI-11 instrument's core channel listens on.

``PortMapper`` is one, over TCP and UDP on one port (111 for clients to find it; tests may
give 0): NULL, SET, UNSET, GETPORT and DUMP; CALLIT (an indirect call) is not offered
(PROC_UNAVAIL). ``announce`` makes a program findable: it registers with the portmapper that
already answers on port 111 (a system rpcbind, or another process's), or, where none answers
and the caller allows it, starts one here; its ``how`` says which.

A mapping is changed only by its owner, as rpcbind does: the process that started the
portmapper (``register``), or the caller that SET it, which is one TCP connection (the
mapping lives as long as that connection: a registrant that dies takes its mappings with
it, and ``announce`` keeps its connection open) or one UDP sender (address and port). SET
and UNSET come only from this machine (loopback); a SET of a triple mapped already is
refused (RFC 1833), an UNSET removes the caller's own mappings only, and every refusal is
told to ``on_event``. A second server of the same program is therefore refused, not let in
over the first: ``announce`` raises ``MappingTaken`` (its owner still answers on the port
mapped), unless the mapped port is dead, when the stale mapping is replaced."""
from __future__ import annotations

import contextlib
import socket
import threading
from collections.abc import Callable
from dataclasses import dataclass

from instruments.errors import InstrumentError
from instruments.transports import oncrpc
from instruments.transports.addresses import is_loopback, peer_text
from instruments.transports.tcp import TcpService
from instruments.transports.wire import Connection, EventKind, EventSink, Limits

PMAP_PROG, PMAP_VERS, PMAP_PORT = 100000, 2, 111
PMAPPROC_SET, PMAPPROC_UNSET, PMAPPROC_GETPORT, PMAPPROC_DUMP = 1, 2, 3, 4
IPPROTO_TCP, IPPROTO_UDP = 6, 17
MAX_RECORD = 4096
"""The largest call a portmapper takes: its arguments are four integers."""
MAX_MAPPINGS, MAX_PER_OWNER = 256, 8
"""The most mappings a portmapper holds, and one owner may hold (a bound on its memory and on
the connections a registrant keeps busy)."""
LOCAL = "this process"
"""The owner of the mappings the process running the portmapper registers in-process."""


class MappingTaken(InstrumentError):
    """The portmapper maps the program to another server's port, whose owner still answers
    there: this one is not registered (``port``: the one mapped)."""

    def __init__(self, text: str, port: int) -> None:
        super().__init__(text)
        self.port = port


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

    def described(self) -> str:
        prot = {IPPROTO_TCP: "tcp", IPPROTO_UDP: "udp"}.get(self.prot, f"protocol {self.prot}")
        return f"program {self.prog} version {self.vers} {prot} port {self.port}"


class PortMapper:
    """A portmapper on (host, port) over TCP and UDP. ``start()`` serves; ``close()`` stops."""

    def __init__(self, host: str = "127.0.0.1", port: int = PMAP_PORT, *, limits: Limits | None = None,
                 on_event: EventSink | None = None) -> None:
        self._table: dict[tuple[int, int, int], tuple[int, str]] = {}  # (prog, vers, prot) -> (port, owner)
        self._guard = threading.Lock()
        self._tcp = TcpService(self._serve_tcp, host, port, name="portmap", limits=limits, on_event=on_event)
        self.host, self.port = self._tcp.host, self._tcp.port
        try:
            self._udp = socket.socket(socket.AF_INET6 if ":" in self.host else socket.AF_INET, socket.SOCK_DGRAM)
        except OSError:
            self._tcp.close()
            raise
        try:
            self._udp.bind((self.host, self.port))
        except OSError:
            self._udp.close()
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
            return [PortMapping(p, v, t, port) for (p, v, t), (port, _) in self._table.items()]

    def register(self, m: PortMapping, owner: str = LOCAL) -> bool:
        """Map (prog, vers, prot) to its port for ``owner``; False when already mapped (RFC
        1833: SET refuses a triple that is mapped, its owner UNSETs it first) or when the
        table (or the owner's share of it) is full."""
        with self._guard:
            key = (m.prog, m.vers, m.prot)
            held = sum(1 for _, o in self._table.values() if o == owner)
            if key in self._table or len(self._table) >= MAX_MAPPINGS or \
                    (owner != LOCAL and held >= MAX_PER_OWNER):
                return False
            self._table[key] = (m.port, owner)
            return True

    def unregister(self, prog: int, vers: int, owner: str = LOCAL) -> tuple[int, int]:
        """Remove ``owner``'s mappings of (prog, vers), every protocol; (how many were
        removed, how many of another owner's were left)."""
        with self._guard:
            keys = [k for k in self._table if k[:2] == (prog, vers)]
            mine = [k for k in keys if self._table[k][1] == owner]
            for k in mine:
                del self._table[k]
            return len(mine), len(keys) - len(mine)

    def _drop_owner(self, owner: str) -> None:
        with self._guard:
            for k in [k for k, (_, o) in self._table.items() if o == owner]:
                del self._table[k]

    def _programs(self, owner: str, peer: str, address: str, report: Callable[[EventKind, str, str], None],
                  pin: Callable[[bool], None] | None = None) -> dict[int, oncrpc.Program]:
        """The portmapper program as ``owner`` (a caller at ``peer``) sees it: SET and UNSET
        its own; ``pin(True)`` when it first holds a mapping, ``pin(False)`` when no more."""
        local = is_loopback(address)

        def refused(what: str, why: str) -> bytes:
            report(EventKind.REFUSED, peer, f"{what}: {why}")
            return bytes(oncrpc.XdrWriter().bool(False))

        def held() -> int:
            with self._guard:
                return sum(1 for _, o in self._table.values() if o == owner)

        def set_(r: oncrpc.XdrReader) -> bytes:
            m = PortMapping.unpacked(r)
            if not local:
                return refused(f"SET of {m.described()}", "only a program of this machine registers (loopback)")
            before = held()
            if not self.register(m, owner):
                with self._guard:
                    mapped = self._table.get((m.prog, m.vers, m.prot))
                if mapped is None:
                    return refused(f"SET of {m.described()}", f"the table is full ({MAX_MAPPINGS} mappings, "
                                                              f"{MAX_PER_OWNER} a caller)")
                if mapped[1] != owner:
                    return refused(f"SET of {m.described()}", f"mapped to port {mapped[0]} by another owner")
                return bytes(oncrpc.XdrWriter().bool(False))  # its own mapping: RFC 1833's plain refusal
            if pin is not None and before == 0:
                pin(True)
            return bytes(oncrpc.XdrWriter().bool(True))

        def unset(r: oncrpc.XdrReader) -> bytes:
            m = PortMapping.unpacked(r)  # UNSET ignores prot and port: every protocol of (prog, vers)
            what = f"UNSET of program {m.prog} version {m.vers}"
            if not local:
                return refused(what, "only a program of this machine unregisters (loopback)")
            before = held()
            removed, others = self.unregister(m.prog, m.vers, owner)
            if pin is not None and before and not held():
                pin(False)
            if others and not removed:
                return refused(what, "mapped by another owner")
            return bytes(oncrpc.XdrWriter().bool(bool(removed)))

        return {PMAP_PROG: oncrpc.Program(PMAP_PROG, PMAP_VERS, PMAP_VERS, {
            PMAPPROC_SET: set_, PMAPPROC_UNSET: unset,
            PMAPPROC_GETPORT: self._getport, PMAPPROC_DUMP: self._dump})}

    def _getport(self, r: oncrpc.XdrReader) -> bytes:
        m = PortMapping.unpacked(r)
        with self._guard:
            port = self._table.get((m.prog, m.vers, m.prot), (0, ""))[0]
        return bytes(oncrpc.XdrWriter().uint(port))

    def _dump(self, r: oncrpc.XdrReader) -> bytes:
        r.done()
        out = oncrpc.XdrWriter()
        for m in self.mappings():  # a linked list: "value follows" before each entry
            out.bool(True).raw(m.packed())
        return bytes(out.bool(False))

    def _serve_tcp(self, conn: socket.socket, peer: str) -> None:
        c: Connection = self._tcp.connection(conn)
        owner = f"tcp {peer}"
        conn.settimeout(self._tcp.limits.stall_timeout_s)
        try:
            oncrpc.serve_connection(conn, self._programs(owner, peer, c.address, self._tcp.report, c.clock.pin),
                                    MAX_RECORD, c)
        finally:  # the connection that made a mapping is gone: so is the mapping
            self._drop_owner(owner)

    def _serve_udp(self) -> None:
        while not self._stop.is_set():
            try:
                datagram, addr = self._udp.recvfrom(MAX_RECORD)
            except TimeoutError:
                continue
            except OSError:
                return
            peer = peer_text(addr)
            reply = oncrpc.answer(datagram, self._programs(f"udp {peer}", peer, str(addr[0]), self._tcp.report))
            if reply is not None:
                with contextlib.suppress(OSError):  # the asker is gone; a UDP caller retries
                    self._udp.sendto(reply, addr)

    def close(self) -> None:
        self._stop.set()
        self._tcp.close()
        with contextlib.suppress(OSError):  # ENOTCONN, yet it wakes the recvfrom() that waits: it ends on the close
            self._udp.shutdown(socket.SHUT_RDWR)
        self._udp.close()
        if self._udp_thread.is_alive():
            self._udp_thread.join(timeout=2.0)


class Announcement:
    """A program made findable through the portmapper on ``port``; ``close()`` unregisters it
    (over the connection that registered it, kept open until then), or, when this
    announcement started that portmapper, stops it (and with it whatever other processes
    registered there meanwhile: the port is this process's until it ends)."""

    def __init__(self, mappings: list[PortMapping], host: str, port: int, started: PortMapper | None,
                 client: oncrpc.RpcClient | None = None) -> None:
        self.mappings, self._host, self.port, self._started, self._client = mappings, host, port, started, client
        self.how = (f"started a portmapper on port {port}" if started else
                    f"registered with the portmapper already answering on port {port}")

    def close(self) -> None:
        if self._started is not None:
            self._started.close()
            self._started = None
            return
        client, self._client = self._client, None
        if client is None:
            return
        try:
            _unset_each(client, self.mappings)
        except (OSError, oncrpc.XdrError):  # that connection broke: another one (a system rpcbind's rules)
            with contextlib.suppress(OSError, oncrpc.XdrError):
                _call_each(self._host, self.port, PMAPPROC_UNSET, self.mappings)
        finally:
            client.close()


def _unset_each(client: oncrpc.RpcClient, mappings: list[PortMapping]) -> None:
    for prog, vers in dict.fromkeys((m.prog, m.vers) for m in mappings):
        client.call(PMAPPROC_UNSET, PortMapping(prog, vers, 0, 0).packed())


def _call_each(host: str, port: int, proc: int, mappings: list[PortMapping]) -> list[bool]:
    client = oncrpc.RpcClient(host, port, PMAP_PROG, PMAP_VERS, timeout_s=2.0)
    try:
        return [client.call(proc, m.packed()).bool() for m in mappings]
    finally:
        client.close()


def answers(host: str, port: int) -> bool:
    """True when something accepts a TCP connection on (host, port)."""
    try:
        socket.create_connection((host, port), timeout=1.0).close()
    except OSError:
        return False
    return True


def getport(host: str, prog: int, vers: int, *, port: int = PMAP_PORT) -> int:
    """The TCP port the portmapper at (host, port) gives (prog, vers); 0 when unregistered."""
    client = oncrpc.RpcClient(host, port, PMAP_PROG, PMAP_VERS, timeout_s=2.0)
    try:
        return client.call(PMAPPROC_GETPORT, PortMapping(prog, vers, IPPROTO_TCP, 0).packed()).uint()
    finally:
        client.close()


def announce(programs: list[tuple[int, int, int]], host: str = "127.0.0.1", *,
             port: int = PMAP_PORT, start: bool = True, limits: Limits | None = None,
             on_event: EventSink | None = None) -> Announcement:
    """Register each (prog, vers, tcp port) with the portmapper answering on (host, port), over
    a connection kept until ``close()``; when none answers and ``start`` is set, start one
    there first (with ``limits`` and ``on_event``). Raises ``MappingTaken`` when a program is
    mapped already to a port whose server still answers, ``InstrumentError`` (one line) when
    neither registering nor starting is possible."""
    mappings = [PortMapping(p, v, IPPROTO_TCP, tcp_port) for p, v, tcp_port in programs]
    try:
        client = oncrpc.RpcClient(host, port, PMAP_PROG, PMAP_VERS, timeout_s=2.0)
    except OSError as e:
        if not start:
            raise InstrumentError(f"portmapper on {host}:{port}: {e}; allowed: a running portmapper "
                                  f"(or let this process start one)") from None
        return _start_here(mappings, host, port, limits, on_event)
    try:
        _register(client, mappings, host, port)
    except BaseException:
        client.close()
        raise
    return Announcement(mappings, host, port, None, client)


def _register(client: oncrpc.RpcClient, mappings: list[PortMapping], host: str, port: int) -> None:
    """SET each mapping over ``client``; a triple mapped already is taken over only when its
    port is dead (a server gone without unregistering) and the portmapper lets this caller
    replace it, else ``MappingTaken`` (what this call had registered is unregistered)."""
    done: list[PortMapping] = []
    try:
        for m in mappings:
            if not client.call(PMAPPROC_SET, m.packed()).bool():
                mapped = client.call(PMAPPROC_GETPORT, m.packed()).uint()
                alive = bool(mapped) and answers(host, mapped)
                if alive or not _replace_stale(client, m):
                    with contextlib.suppress(OSError, oncrpc.XdrError):
                        _unset_each(client, done)
                    owner = "which answers there" if alive else "whose owner keeps it"
                    raise MappingTaken(f"portmapper on {host}:{port} maps program {m.prog} version {m.vers} to "
                                       f"port {mapped}, another server's, {owner}: this one is not registered; "
                                       f"allowed: one server a program on one portmapper (another on an "
                                       f"address of its own, or named by its port)", mapped)
            done.append(m)
    except (OSError, oncrpc.XdrError) as e:
        raise InstrumentError(f"portmapper on {host}:{port}: {e}; allowed: a portmapper that takes SET") from None


def _replace_stale(client: oncrpc.RpcClient, m: PortMapping) -> bool:
    """UNSET a mapping whose server is gone and SET ``m`` in its place; False when the
    portmapper refuses (it is another owner's)."""
    client.call(PMAPPROC_UNSET, m.packed())
    return client.call(PMAPPROC_SET, m.packed()).bool()


def _start_here(mappings: list[PortMapping], host: str, port: int, limits: Limits | None,
                on_event: EventSink | None) -> Announcement:
    try:
        mapper = PortMapper(host, port, limits=limits, on_event=on_event).start()
    except OSError as e:
        raise InstrumentError(f"portmapper port = {port}: cannot be bound here ({e.strerror}) and no "
                              f"portmapper answers on it; clients must name the port "
                              f"(TCPIP::{host},PORT::INSTR)") from None
    for m in mappings:
        mapper.register(m)
    return Announcement(mappings, host, mapper.port, mapper)
