"""The portmapper (instruments/transports/portmap.py), asked by pyvisa-py's own portmapper
clients over TCP and UDP, on a free port (port 111 is the VXI-11 tests' alone)."""
import socket

import pytest
from pyvisa_py.protocols import rpc

from instruments.errors import InstrumentError
from instruments.transports import portmap

CORE = 0x0607AF


class TcpAsker(rpc.PartialPortMapperClient, rpc.RawTCPClient):
    """pyvisa-py's portmapper client, on another port than 111."""

    def __init__(self, port, host="127.0.0.1"):
        rpc.RawTCPClient.__init__(self, host, rpc.PMAP_PROG, rpc.PMAP_VERS, port)
        rpc.PartialPortMapperClient.__init__(self)


class UdpAsker(rpc.PartialPortMapperClient, rpc.RawUDPClient):
    def __init__(self, port):
        rpc.RawUDPClient.__init__(self, "127.0.0.1", rpc.PMAP_PROG, rpc.PMAP_VERS, port)
        rpc.PartialPortMapperClient.__init__(self)


@pytest.fixture
def mapper():
    m = portmap.PortMapper(port=0).start()
    yield m
    m.close()


@pytest.mark.parametrize("asker", [TcpAsker, UdpAsker])
def test_set_getport_dump_unset_as_a_client_sees_them(mapper, asker):
    c = asker(mapper.port)
    try:
        assert c.get_port((CORE, 1, rpc.IPPROTO_TCP, 0)) == 0
        assert c.set((CORE, 1, rpc.IPPROTO_TCP, 4321)) == 1
        assert c.set((CORE, 1, rpc.IPPROTO_TCP, 9999)) == 0  # mapped already: refused
        assert c.set((CORE, 1, rpc.IPPROTO_UDP, 4322)) == 1
        assert c.get_port((CORE, 1, rpc.IPPROTO_TCP, 0)) == 4321
        assert c.get_port((CORE, 2, rpc.IPPROTO_TCP, 0)) == 0
        assert sorted(c.dump()) == [(CORE, 1, rpc.IPPROTO_TCP, 4321), (CORE, 1, rpc.IPPROTO_UDP, 4322)]
        assert c.unset((CORE, 1, 0, 0)) == 1  # every protocol of (prog, vers)
        assert c.dump() == [] and c.unset((CORE, 1, 0, 0)) == 0
    finally:
        c.close()


def test_a_garbage_datagram_is_ignored_and_the_mapper_keeps_answering(mapper):
    s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    s.sendto(b"\x00\x01", ("127.0.0.1", mapper.port))
    s.close()
    c = UdpAsker(mapper.port)
    assert c.get_port((CORE, 1, rpc.IPPROTO_TCP, 0)) == 0
    c.close()


def test_announce_registers_with_a_running_mapper_and_close_unregisters(mapper):
    """A second server of the same program is refused, not let in over the first (which
    had won before): the first keeps its entry until it unregisters it itself."""
    a = portmap.announce([(CORE, 1, 5555)], port=mapper.port, start=False)
    assert a.how == f"registered with the portmapper already answering on port {mapper.port}"
    assert portmap.getport("127.0.0.1", CORE, 1, port=mapper.port) == 5555
    with pytest.raises(portmap.MappingTaken, match="maps program 395183 version 1 to port 5555") as taken:
        portmap.announce([(CORE, 1, 6666)], port=mapper.port)
    assert taken.value.port == 5555
    assert portmap.getport("127.0.0.1", CORE, 1, port=mapper.port) == 5555
    a.close()
    assert mapper.mappings() == []


def test_announce_starts_a_mapper_where_none_answers_and_close_stops_it():
    probe = socket.create_server(("127.0.0.1", 0))
    free = probe.getsockname()[1]
    probe.close()
    with pytest.raises(InstrumentError, match=f"portmapper on 127.0.0.1:{free}:.*allowed"):
        portmap.announce([(CORE, 1, 5555)], port=free, start=False)
    a = portmap.announce([(CORE, 1, 5555)], port=free)
    assert a.how == f"started a portmapper on port {free}"
    assert portmap.getport("127.0.0.1", CORE, 1, port=free) == 5555
    a.close()
    with pytest.raises(ConnectionRefusedError):
        socket.create_connection(("127.0.0.1", free), timeout=2.0)


def test_a_mapping_is_changed_only_by_its_owner_and_each_refusal_is_told(mapper):
    events = []
    owned = portmap.PortMapper(port=0, on_event=events.append).start()
    try:
        a = portmap.announce([(CORE, 1, 5555)], port=owned.port, start=False)
        stranger = TcpAsker(owned.port)
        try:
            assert stranger.unset((CORE, 1, 0, 0)) == 0  # not its own: nothing removed
            assert stranger.set((CORE, 1, rpc.IPPROTO_TCP, 7777)) == 0
            assert stranger.set((CORE, 1, rpc.IPPROTO_UDP, 7778)) == 1  # a triple nobody holds is its own
            assert stranger.unset((CORE, 1, 0, 0)) == 1  # removes its own UDP one only
        finally:
            stranger.close()
        assert portmap.getport("127.0.0.1", CORE, 1, port=owned.port) == 5555
        a.close()
        assert owned.mappings() == []
    finally:
        owned.close()
    refused = [e.detail for e in events if e.kind.value == "refused"]
    assert refused == ["UNSET of program 395183 version 1: mapped by another owner",
                       "SET of program 395183 version 1 tcp port 7777: mapped to port 5555 by another owner"]


def test_a_tcp_registration_lives_as_long_as_its_connection(mapper, eventually):
    c = TcpAsker(mapper.port)
    assert c.set((CORE, 1, rpc.IPPROTO_TCP, 4321)) == 1
    assert portmap.getport("127.0.0.1", CORE, 1, port=mapper.port) == 4321
    c.close()  # its registrant is gone (ended, crashed): no stale entry is left behind
    assert eventually(lambda: mapper.mappings() == [])
    b = portmap.announce([(CORE, 1, 6666)], port=mapper.port, start=False)
    assert portmap.getport("127.0.0.1", CORE, 1, port=mapper.port) == 6666
    b.close()


def test_a_registration_with_the_portmapper_of_the_process_that_started_it_is_its_own(mapper):
    """In-process registrations (the server that started the portmapper) cannot be unset
    over the wire by anyone."""
    assert mapper.register(portmap.PortMapping(CORE, 1, rpc.IPPROTO_TCP, 1234))
    for asker in (TcpAsker, UdpAsker):
        c = asker(mapper.port)
        assert c.unset((CORE, 1, 0, 0)) == 0
        c.close()
    assert portmap.getport("127.0.0.1", CORE, 1, port=mapper.port) == 1234


def test_set_from_another_machine_is_refused():
    from instruments.transports.addresses import machine_addresses

    address = machine_addresses("0.0.0.0")[0]
    events = []
    m = portmap.PortMapper("0.0.0.0", 0, on_event=events.append).start()
    try:
        try:
            asker = TcpAsker(m.port, address)
        except OSError:
            pytest.skip("no address of this machine other than loopback to call from")
        assert asker.set((CORE, 1, rpc.IPPROTO_TCP, 4321)) == 0
        assert asker.get_port((CORE, 1, rpc.IPPROTO_TCP, 0)) == 0
        asker.close()
    finally:
        m.close()
    assert any("SET of program 395183 version 1 tcp port 4321: only a program of this machine registers" in e.detail
               for e in events)
