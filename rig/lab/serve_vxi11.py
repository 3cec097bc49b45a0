"""VXI-11 of ``rig serve scope`` made findable through the portmapper (rig/lab/serve.py).

A VXI-11 server registers with the portmapper on port 111 of its address (or starts one
there). Where the loopback portmapper already maps another server's VXI-11 (a second
``--vxi11`` server on this machine), this one moves to a loopback address of its own,
127.0.0.2, 127.0.0.3, ..., with a portmapper there, so that both are found and neither
unregisters the other (the portmapper's mapping is changed only by its owner). Without a
portmapper, clients name the core port."""
from __future__ import annotations

from collections.abc import Callable

from instruments.errors import InstrumentError
from instruments.transports.addresses import LOOPBACK_V4
from instruments.transports.portmap import MappingTaken
from instruments.transports.vxi11 import Vxi11Server

VXI11_ADDRESSES = 8
"""Loopback addresses (127.0.0.2 on) a second VXI-11 server tries for a portmapper of its own."""


def announce(vx: Vxi11Server, portmapper_port: int, tell: Callable[[str], None],
             make_at: Callable[[str], Vxi11Server]) -> Vxi11Server:
    """Register ``vx`` with the portmapper; where another server's VXI-11 holds the loopback
    one, the server ``make_at`` starts on a loopback address of its own instead (``vx`` is
    then the caller's to close). The server that serves VXI-11; each step said by ``tell``."""
    try:
        tell(f"VXI-11: {vx.announce(portmapper_port=portmapper_port)}")
        return vx
    except MappingTaken as e:
        moved = elsewhere(e.port, portmapper_port, tell, make_at) if vx.host == LOOPBACK_V4 else None
        if moved is None:
            tell(f"VXI-11: {e}")
            return vx
        return moved
    except InstrumentError as e:  # no portmapper: clients name the core port
        tell(f"VXI-11: {e}")
        return vx


def elsewhere(taken: int, portmapper_port: int, tell: Callable[[str], None],
              make_at: Callable[[str], Vxi11Server]) -> Vxi11Server | None:
    """VXI-11 on 127.0.0.2, 127.0.0.3, ... with a portmapper there (``make_at(address)``
    starts a server); None when no loopback address of this machine takes it (one
    portmapper answering on all of them, or no such address, as off Linux)."""
    for last in range(2, 2 + VXI11_ADDRESSES):
        address = f"127.0.0.{last}"
        try:
            vx = make_at(address)
        except (InstrumentError, OSError):
            return None
        try:
            how = vx.announce(portmapper_port=portmapper_port)
        except MappingTaken as e:
            vx.close()
            if e.port == taken:  # the same portmapper answers there: no address of its own helps
                return None
            continue
        except InstrumentError:
            vx.close()
            continue
        tell(f"VXI-11: the portmapper on {LOOPBACK_V4} port {portmapper_port} maps another server's "
             f"VXI-11 (core port {taken}): this one moves to {address}, a loopback address of its own")
        tell(f"VXI-11 core channel on {vx.host} port {vx.port}")
        tell(f"VXI-11 abort channel on {vx.host} port {vx.abort_port}")
        tell(f"VXI-11: {how}")
        return vx
    return None
