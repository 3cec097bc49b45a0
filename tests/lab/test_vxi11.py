"""VXI-11 (instruments/transports/vxi11.py) driven by real clients: pyvisa with pyvisa-py
(``TCPIP::127.0.0.1::INSTR``, found through the portmapper on port 111), python-vxi11, and
pyvisa-py's RPC core client for the calls a VISA session does not expose (flags, request
sizes, raw error codes). The instrument behind them is tests/lab/vxi11_instrument.py.

Port 111 is one per machine: the session fixture takes it once (or registers with the
portmapper already there) and gives it back at the end, so two runs in a row do not collide."""
import socket
import threading
import time

import pytest
import pyvisa
import vxi11 as python_vxi11
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from pyvisa_py.protocols import vxi11 as v
from pyvisa_py.tcpip import Vxi11CoreClient

from instruments.errors import InstrumentError
from instruments.transports import oncrpc, portmap
from instruments.transports.vxi11 import Vxi11Server
from instruments.transports.vxi11_codec import DEVICE_CORE_PROG
from lab.vxi11_instrument import IDN, EchoInstrument, block

MAX_MESSAGE = 4096
HOST = "127.0.0.1"


class Served:
    def __init__(self):
        self.instrument = EchoInstrument(max_message_bytes=MAX_MESSAGE)
        self.server = Vxi11Server(self.instrument).start()
        try:
            self.how = self.server.announce()
        except InstrumentError as e:  # no root, no portmapper: the direct-port tests still run
            self.how, self.why_not = None, str(e)


@pytest.fixture(scope="module")
def served(port111):
    s = Served()
    yield s
    s.server.close()


@pytest.fixture
def visa(served, rm):
    """A pyvisa session through the portmapper, as a lab script opens one."""
    if served.how is None:
        pytest.skip(f"VXI-11 through port 111 needs a portmapper: {served.why_not}")
    r = rm.open_resource(f"TCPIP::{HOST}::INSTR", timeout=3000)
    yield r
    r.close()


@pytest.fixture
def core(served):
    """pyvisa-py's RPC client on the core channel's port, and a fresh link on it."""
    client = Vxi11CoreClient(HOST, served.server.port)
    error, link, _, _ = client.create_link(1, 0, 0, "inst0")
    assert error == 0
    yield client, link
    client.destroy_link(link)
    client.close()


def test_pyvisa_finds_the_instrument_through_port_111_and_queries(served, visa):
    assert served.how in ("started a portmapper on port 111",
                          "registered with the portmapper already answering on port 111")
    assert portmap.getport(HOST, DEVICE_CORE_PROG, 1) == served.server.port
    assert served.server.resource == "TCPIP::127.0.0.1::INSTR"
    assert visa.query("*IDN?").strip() == IDN.decode()
    visa.write("ECHO? lab script")
    assert visa.read() == "lab script\n"


def test_python_vxi11_queries_through_the_portmapper(served):
    if served.how is None:
        pytest.skip(served.why_not)
    inst = python_vxi11.Instrument(HOST)
    try:
        assert inst.ask("*IDN?") == IDN.decode()
        assert inst.ask("ECHO? " + "x" * 3000) == "x" * 3000
    finally:
        inst.close()


def test_a_megabyte_reply_comes_whole_through_pyvisa_and_in_several_reads(served, visa, core):
    n = 1_000_000
    data = visa.query_binary_values(f"DATA? {n}", datatype="B", container=bytes)
    assert data == block(n)
    client, link = core
    assert client.device_write(link, 1000, 0, v.OP_FLAG_END, f"DATA? {n}".encode()) == (0, 13)
    parts, reasons = [], []
    while not reasons or not reasons[-1] & v.RX_END:
        error, reason, chunk = client.device_read(link, 65536, 2000, 0, 0, 0)
        assert error == 0
        parts.append(chunk)
        reasons.append(reason)
    whole = b"".join(parts)
    assert whole == b"#7%d" % n + block(n) + b"\n"
    assert len(parts) == -(-len(whole) // 65536) == 16  # 65536-byte reads, the last one short
    assert all(r == v.RX_REQCNT for r in reasons[:-1]) and reasons[-1] == v.RX_END


def test_a_read_stops_at_the_termination_character_when_the_client_sets_one(core):
    client, link = core
    client.device_write(link, 1000, 0, v.OP_FLAG_END, b"DATA? 300")
    # the block holds byte 10 (newline) at payload index 10: after the 5-byte "#3300"
    error, reason, data = client.device_read(link, 1000, 1000, 0, v.OP_FLAG_TERMCHAR_SET, 10)
    assert (error, reason, data) == (0, v.RX_CHR, b"#3300" + block(11))
    error, reason, rest = client.device_read(link, 1000, 1000, 0, 0, 0)
    assert (error, reason, data + rest) == (0, v.RX_END, b"#3300" + block(300) + b"\n")


def test_a_message_in_several_writes_is_joined_at_the_end_flag(core):
    client, link = core
    assert client.device_write(link, 1000, 0, 0, b"ECHO? ab") == (0, 8)
    assert client.device_write(link, 1000, 0, 0, b"cd") == (0, 2)
    assert client.device_write(link, 1000, 0, v.OP_FLAG_END, b"ef") == (0, 2)
    assert client.device_read(link, 100, 1000, 0, 0, 0) == (0, v.RX_END, b"abcdef\n")


def test_read_with_nothing_queued_times_out_with_error_15_after_io_timeout(core):
    client, link = core
    t0 = time.monotonic()
    error, reason, data = client.device_read(link, 100, 300, 0, 0, 0)
    elapsed = time.monotonic() - t0
    assert (error, reason, data) == (v.ErrorCodes.io_timeout, 0, b"")
    assert 0.25 < elapsed < 1.5


def test_status_byte_has_mav_while_a_response_waits_and_eav_with_an_error(served, visa):
    assert visa.read_stb() & 0x14 == 0
    visa.write("*IDN?")
    deadline = time.monotonic() + 2
    while not visa.read_stb() & 0x10 and time.monotonic() < deadline:
        time.sleep(0.01)
    assert visa.read_stb() & 0x10
    visa.read()
    assert visa.read_stb() & 0x10 == 0
    visa.write("NOSUCH?")
    assert visa.query("*IDN?").strip() == IDN.decode()  # the queries after it still answer
    assert visa.read_stb() & 0x04
    assert visa.query("SYST:ERR?").startswith("-113")
    assert visa.read_stb() & 0x14 == 0


def test_device_clear_drops_the_unread_response_and_reaches_the_instrument(served, visa):
    clears = served.instrument.clears
    visa.write("ECHO? stale")
    time.sleep(0.05)
    visa.clear()
    assert served.instrument.clears == clears + 1
    visa.timeout = 300
    with pytest.raises(pyvisa.VisaIOError, match="TMO"):
        visa.read()
    visa.timeout = 3000
    assert visa.query("ECHO? fresh") == "fresh\n"


def test_trigger_reaches_the_instrument_from_both_clients(served, visa):
    before = served.instrument.triggers
    visa.assert_trigger()
    inst = python_vxi11.Instrument(HOST)
    inst.trigger()
    inst.close()
    assert served.instrument.triggers == before + 2
    assert visa.query("TRG?").strip() == str(before + 2)


def test_a_lock_refuses_other_links_at_once_or_after_their_lock_timeout(served):
    owner = Vxi11CoreClient(HOST, served.server.port)
    other = Vxi11CoreClient(HOST, served.server.port)
    try:
        _, a, _, _ = owner.create_link(1, 0, 0, "inst0")
        _, b, _, _ = other.create_link(2, 0, 0, "inst0")
        assert owner.device_lock(a, 0, 0) == 0
        assert other.device_lock(b, 0, 0) == v.ErrorCodes.device_locked_by_another_link
        assert other.device_write(b, 1000, 0, v.OP_FLAG_END, b"*IDN?") == (11, 0)
        t0 = time.monotonic()  # with the wait-lock flag: refused after lock_timeout, not before
        assert other.device_write(b, 1000, 300, v.OP_FLAG_END | 1, b"*IDN?") == (11, 0)
        assert 0.25 < time.monotonic() - t0 < 1.5
        assert other.create_link(3, 1, 200, "inst0")[0] == 11  # create_link with lock_device
        assert owner.device_write(a, 1000, 0, v.OP_FLAG_END, b"ECHO? mine") == (0, 10)
        assert owner.device_read(a, 100, 1000, 0, 0, 0)[2] == b"mine\n"
        # the owner lets go while the other waits for the lock: the other's write goes through
        threading.Timer(0.2, owner.device_unlock, args=(a,)).start()
        t0 = time.monotonic()
        assert other.device_write(b, 1000, 3000, v.OP_FLAG_END | 1, b"ECHO? yours") == (0, 11)
        assert 0.15 < time.monotonic() - t0 < 2.0
        assert other.device_read(b, 100, 1000, 0, 0, 0)[2] == b"yours\n"
        assert owner.device_unlock(a) == v.ErrorCodes.no_lock_held_by_this_link
        other.destroy_link(b)
        owner.destroy_link(a)
    finally:
        owner.close()
        other.close()
    assert not served.instrument.lock.blocks(object())  # destroy_link let the lock go


def test_python_vxi11_lock_holds_against_a_pyvisa_session(served, visa):
    inst = python_vxi11.Instrument(HOST)
    try:
        inst.lock()
        with pytest.raises(pyvisa.VisaIOError):
            visa.write("ECHO? blocked")
        inst.unlock()
        assert visa.query("ECHO? free") == "free\n"
    finally:
        inst.close()


def test_a_message_over_the_instruments_size_is_discarded_and_reported(served, visa):
    message = "ECHO? " + "y" * (MAX_MESSAGE + 100) + visa.write_termination
    visa.write_raw(message.encode())
    assert visa.query("SYST:ERR?").strip() == f'-223,"Too much data; {len(message)} bytes"'
    assert visa.query("*IDN?").strip() == IDN.decode()


def test_write_data_over_max_recv_size_is_refused_and_an_oversize_record_closes_only_its_link(served):
    client = Vxi11CoreClient(HOST, served.server.port)
    _, link, _, _ = client.create_link(1, 0, 0, "inst0")
    size = served.server.max_recv_size
    assert client.device_write(link, 1000, 0, v.OP_FLAG_END, b"x" * (size + 1)) == (5, 0)
    links = served.server.links
    try:  # the record itself is over the bound: the server hangs up, unanswered
        error = client.device_write(link, 1000, 0, v.OP_FLAG_END, b"x" * (size + 2048))[0]
    except OSError:  # pyvisa-py reports a reset connection by raising, a silent one as an I/O error
        error = v.ErrorCodes.io_error
    assert error == v.ErrorCodes.io_error
    deadline = time.monotonic() + 2
    while served.server.links >= links and time.monotonic() < deadline:
        time.sleep(0.02)
    assert served.server.links == links - 1
    client.close()
    fresh = Vxi11CoreClient(HOST, served.server.port)
    _, other, _, _ = fresh.create_link(1, 0, 0, "inst0")
    fresh.device_write(other, 1000, 0, v.OP_FLAG_END, b"*IDN?")
    assert fresh.device_read(other, 100, 1000, 0, 0, 0)[2] == IDN + b"\n"
    fresh.destroy_link(other)
    fresh.close()


def test_a_slow_message_runs_while_the_link_still_answers_out_of_band_and_the_next_waits(core):
    client, link = core
    t0 = time.monotonic()
    assert client.device_write(link, 1000, 0, v.OP_FLAG_END, b"SLEEP 0.6") == (0, 9)
    assert client.device_read_stb(link, 0, 0, 1000) == (0, 0)  # answered during the slow command
    assert time.monotonic() - t0 < 0.3
    # one message at a time: the next one is not taken before the slow one ends
    assert client.device_write(link, 100, 0, v.OP_FLAG_END, b"ECHO? next") == (v.ErrorCodes.io_timeout, 0)
    assert client.device_write(link, 3000, 0, v.OP_FLAG_END, b"ECHO? next") == (0, 10)
    assert time.monotonic() - t0 > 0.55
    assert client.device_read(link, 100, 1000, 0, 0, 0) == (0, v.RX_END, b"next\n")


def test_links_are_bounded_the_one_over_gets_out_of_resources():
    events = []
    server = Vxi11Server(EchoInstrument(), max_links=2, on_event=events.append).start()
    client = Vxi11CoreClient(HOST, server.port)
    try:
        assert [client.create_link(k, 0, 0, "inst0")[0] for k in range(3)] == [0, 0, v.ErrorCodes.out_of_resources]
        assert server.links == 2
        assert client.create_link(9, 0, 0, "gpib0,5")[0] == v.ErrorCodes.device_not_accessible
    finally:
        client.close()
        server.close()
    refused = [e.detail for e in events if e.kind.value == "refused"]  # each refusal is told, with its error
    assert refused == ["create_link: 2 links open: allowed at most 2 (VXI-11 error 9)",
                       "create_link: device name 'gpib0,5': allowed inst0 (VXI-11 error 3)"]


def test_a_port_in_use_is_refused_in_one_line(served):
    with pytest.raises(InstrumentError, match=f"^VXI-11 port = {served.server.port}: cannot listen on "
                                              f"127.0.0.1 .*allowed: a free port, or 0 for any$"):
        Vxi11Server(EchoInstrument(), port=served.server.port)


def test_link_errors_name_what_is_wrong(served, core):
    client, link = core
    assert client.device_write(9999, 1000, 0, v.OP_FLAG_END, b"*IDN?") == (4, 0)
    assert client.device_read(9999, 10, 100, 0, 0, 0)[0] == 4
    assert client.device_read_stb(9999, 0, 0, 100) == (4, 0)
    assert client.destroy_link(9999) == 4
    assert client.create_link(1, 0, 0, "gpib0,5")[0] == v.ErrorCodes.device_not_accessible
    their = python_vxi11.vxi11.CoreClient(HOST, served.server.port)  # pyvisa-py's packs it wrong
    assert their.create_intr_chan(0x7F000001, 1234, 0x0607B1, 1, 0) == v.ErrorCodes.operation_not_supported
    assert their.destroy_intr_chan() == v.ErrorCodes.channel_not_established
    their.close()
    assert client.device_enable_srq(link, 1, b"h") == v.ErrorCodes.operation_not_supported


def test_device_abort_ends_a_waiting_read_with_error_23(served, core):
    client, link = core
    result = {}
    t = threading.Thread(target=lambda: result.update(r=client.device_read(link, 100, 5000, 0, 0, 0)))
    t0 = time.monotonic()
    t.start()
    time.sleep(0.2)
    abort = python_vxi11.vxi11.AbortClient(HOST, served.server.abort_port)
    assert abort.device_abort(link) == 0
    abort.close()
    t.join(3)
    assert result["r"][0] == v.ErrorCodes.abort and time.monotonic() - t0 < 2.0


def _raw_call(sock, proc, args):
    """Send one core-channel call by hand (a client that may vanish before the reply)."""
    head = (oncrpc.XdrWriter().uint(7).uint(0).uint(2).uint(DEVICE_CORE_PROG).uint(1).uint(proc)
            .uint(0).opaque(b"").uint(0).opaque(b""))
    oncrpc.write_record(sock, bytes(head) + bytes(args))


def test_a_client_that_vanishes_mid_call_frees_its_link_and_lock(served):
    sessions, links = served.instrument.sessions_open, served.server.links
    sock = socket.create_connection((HOST, served.server.port), timeout=5.0)
    _raw_call(sock, v.CREATE_LINK, oncrpc.XdrWriter().int(1).bool(True).uint(0).string(b"inst0"))
    reply = oncrpc.XdrReader(oncrpc.read_record(sock, 1024))
    for _ in range(6):  # xid, reply, accepted, verifier (flavor, empty body), success
        reply.uint()
    assert reply.int() == 0  # the link is made and holds the lock
    link = reply.int()
    assert served.server.links == links + 1 and served.instrument.lock.blocks(object())
    # a read that waits 10 s for a response that never comes; the client goes meanwhile
    _raw_call(sock, v.DEVICE_READ, oncrpc.XdrWriter().int(link).uint(100).uint(10_000).uint(0).int(0).int(0))
    time.sleep(0.2)
    sock.close()
    t0 = time.monotonic()
    while served.server.links > links and time.monotonic() - t0 < 3:
        time.sleep(0.02)
    assert time.monotonic() - t0 < 1.0  # noticed within the server's poll, not after 10 s
    assert served.server.links == links and served.instrument.sessions_open == sessions
    assert not served.instrument.lock.blocks(object())


def test_sixteen_links_at_once_each_get_their_own_answers(served, rm):
    if served.how is None:
        pytest.skip(served.why_not)
    base = served.server.links
    sessions = [rm.open_resource(f"TCPIP::{HOST}::INSTR", timeout=5000) for _ in range(16)]
    assert served.server.links == base + 16
    wrong = []

    def talk(k, r):
        for i in range(20):
            answer = r.query(f"ECHO? {k}-{i}")
            if answer != f"{k}-{i}\n":
                wrong.append((k, i, answer))

    threads = [threading.Thread(target=talk, args=(k, r)) for k, r in enumerate(sessions)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(30)
    for r in sessions:
        r.close()
    assert wrong == []
    assert served.server.links == base


def test_close_stops_both_channels_ends_links_and_unregisters():
    mapper = portmap.PortMapper(port=0).start()
    instrument = EchoInstrument()
    server = Vxi11Server(instrument).start()
    try:
        how = server.announce(portmapper_port=mapper.port)
        assert how == f"registered with the portmapper already answering on port {mapper.port}"
        assert portmap.getport(HOST, DEVICE_CORE_PROG, 1, port=mapper.port) == server.port
        client = Vxi11CoreClient(HOST, server.port)
        _, link, _, _ = client.create_link(1, 1, 0, "inst0")
        server.close()
        assert server.links == 0 and instrument.sessions_open == 0
        assert not instrument.lock.blocks(object())
        assert mapper.mappings() == []
        for port in (server.port, server.abort_port):
            with pytest.raises(ConnectionRefusedError):
                socket.create_connection((HOST, port), timeout=2.0)
        # the client's connection was shut down: its call fails (pyvisa-py reports an I/O error
        # after io_timeout and a second of its own: an io_timeout of 0 leaves its second)
        assert client.device_write(link, 0, 0, v.OP_FLAG_END, b"*IDN?")[0] == v.ErrorCodes.io_error
        client.close()
    finally:
        server.close()
        mapper.close()


@pytest.fixture(scope="module")
def fuzzed():
    """A server of its own (no link of the other tests to stumble on) and one connection."""
    server = Vxi11Server(EchoInstrument()).start()
    sock = socket.create_connection((HOST, server.port), timeout=5.0)
    yield server, sock
    sock.close()
    server.close()


@settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(proc=st.sampled_from([10, 11, 12, 13, 14, 15, 16, 17, 18, 19, 20, 21, 22, 23, 24, 25, 26, 99]),
       args=st.binary(max_size=80))
def test_random_arguments_get_an_rpc_answer_and_leave_the_server_serving(fuzzed, proc, args):
    server, sock = fuzzed
    _raw_call(sock, proc, args)
    reply = oncrpc.XdrReader(oncrpc.read_record(sock, 1 << 16))
    xid, kind, accepted, _, _ = reply.uint(), reply.uint(), reply.uint(), reply.uint(), reply.opaque()
    assert (xid, kind, accepted) == (7, 1, 0)
    status = reply.uint()
    assert status in (oncrpc.SUCCESS, oncrpc.GARBAGE_ARGS, oncrpc.PROC_UNAVAIL)
    assert (status == oncrpc.PROC_UNAVAIL) == (proc in (21, 24, 99))
    if status == oncrpc.SUCCESS:  # well-formed by chance: an error code of VXI-11's, or a link
        assert reply.int() in (0, 3, 4, 5, 6, 8, 9, 11, 12, 15, 17, 23)
    assert server.links == 0 or proc == 10
