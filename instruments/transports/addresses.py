"""Addresses as the transports listen on them and as VISA names them: which family an
address is (IPv4 or IPv6), whether it is loopback or a wildcard, how a resource string
writes it (``[::1]`` for IPv6), and which addresses of this machine a remote client can
open when a server listens on a wildcard (``0.0.0.0``, ``::``)."""
from __future__ import annotations

import contextlib
import ipaddress
import socket

LOOPBACK_V4 = "127.0.0.1"
PROBES = (("192.0.2.1", socket.AF_INET), ("2001:db8::1", socket.AF_INET6))
"""Documentation addresses (RFC 5737, 3849) a UDP socket is pointed at to learn which address of
this machine its route leaves from; no packet is sent."""


def resolve(host: str) -> tuple[socket.AddressFamily, str]:
    """(family, numeric address) to listen on for ``host`` (an address or a name); raises
    ``OSError`` (``socket.gaierror``) when it names nothing."""
    infos = socket.getaddrinfo(host, None, socket.AF_UNSPEC, socket.SOCK_STREAM, 0, socket.AI_PASSIVE)
    family, _, _, _, sockaddr = infos[0]
    return socket.AddressFamily(family), str(sockaddr[0])


def _ip(address: str) -> ipaddress.IPv4Address | ipaddress.IPv6Address | None:
    try:
        ip = ipaddress.ip_address(address.split("%", 1)[0])
    except ValueError:
        return None
    if isinstance(ip, ipaddress.IPv6Address) and ip.ipv4_mapped is not None:
        return ip.ipv4_mapped  # ::ffff:127.0.0.1, an IPv4 client of a dual-stack listener
    return ip


def is_loopback(address: str) -> bool:
    """True for 127.0.0.0/8 and ::1 (and ``localhost``-style names that resolve there)."""
    ip = _ip(address)
    if ip is None:
        try:
            ip = _ip(resolve(address)[1])
        except OSError:
            return False
    return ip is not None and ip.is_loopback


def is_wildcard(address: str) -> bool:
    """True for 0.0.0.0 and ::, every address of this machine."""
    ip = _ip(address)
    return ip is not None and ip.is_unspecified


def visa_host(address: str) -> str:
    """``address`` as a VISA resource string writes it: an IPv6 literal in brackets."""
    return f"[{address}]" if ":" in address else address


def peer_text(sockaddr: tuple) -> str:
    """``host:port`` of a peer (``[v6]:port`` for IPv6)."""
    return f"{visa_host(str(sockaddr[0]))}:{sockaddr[1]}"


def machine_addresses(wildcard: str, most: int = 4) -> list[str]:
    """The addresses of this machine a remote client may open when a server listens on
    ``wildcard`` (0.0.0.0: IPv4 ones; ::, dual stack: IPv6 and IPv4 ones), loopback left
    out; the machine's name when none is found."""
    families = [socket.AF_INET] if ":" not in wildcard else [socket.AF_INET6, socket.AF_INET]
    found: list[str] = []
    for target, family in PROBES:
        if family not in families:
            continue
        with contextlib.suppress(OSError), socket.socket(family, socket.SOCK_DGRAM) as probe:
            probe.connect((target, 9))  # a route lookup only: UDP sends nothing on connect
            found.append(str(probe.getsockname()[0]))
    with contextlib.suppress(OSError):
        for family, _, _, _, sockaddr in socket.getaddrinfo(socket.gethostname(), None, socket.AF_UNSPEC,
                                                            socket.SOCK_STREAM):
            if family in families:
                found.append(str(sockaddr[0]))
    usable = [a for a in dict.fromkeys(found) if not is_loopback(a) and not is_wildcard(a)
              and not a.lower().startswith("fe80:")]  # a link-local address needs its interface named
    return usable[:most] or [socket.gethostname()]
