"""The raw-socket server (instruments/transports/socket.py) through pyvisa + pyvisa-py's
``TCPIP::host::port::SOCKET`` resource and plain sockets, against the echo instrument."""
import socket
import threading
import time

import pytest
from pyvisa.errors import VisaIOError

from instruments.transports.hislip import HislipServer
from instruments.transports.socket import MessageFramer, SocketServer
from instruments.transports.wire import EventKind, Limits
from lab.many_clients import talk_at_once


@pytest.fixture
def server(instrument):
    srv = SocketServer(instrument).start()
    yield srv
    srv.close()


def open_socket(rm, port, timeout_ms=3000):
    inst = rm.open_resource(f"TCPIP::127.0.0.1::{port}::SOCKET", read_termination="\n",
                            write_termination="\n", timeout=timeout_ms)
    return inst


def test_write_and_query(rm, server, instrument):
    inst = open_socket(rm, server.port)
    assert inst.query("*IDN?") == instrument.IDN.decode()
    inst.write("NOT:A:COMMAND")  # a command: no reply, an error queued
    assert inst.query("ECHO? hello world") == "hello world"
    assert inst.query("SYST:ERR?").startswith("-113,")
    assert inst.query("SYST:ERR?") == '0,"No error"'


def test_one_megabyte_reply_arrives_whole(rm, server, instrument):
    inst = open_socket(rm, server.port, timeout_ms=10000)
    data = inst.query_binary_values("DATA? 1000000", datatype="B", container=bytes)
    assert len(data) == 1_000_000 and data == instrument.pattern(1_000_000)
    assert inst.query("*IDN?") == instrument.IDN.decode()  # nothing of the block was left behind


def test_many_queries_in_a_row_keep_their_order(rm, server):
    inst = open_socket(rm, server.port)
    assert [inst.query(f"ECHO? {k}") for k in range(200)] == [str(k) for k in range(200)]


def test_messages_in_pieces_several_in_one_send_and_crlf(server):
    with socket.create_connection(("127.0.0.1", server.port), timeout=3) as s:
        for piece in (b"EC", b"HO? a", b"b\r", b"\nECHO? c\nECHO? d\r\n"):
            s.sendall(piece)
            time.sleep(0.05)
        replies = b""
        while replies.count(b"\n") < 3:
            replies += s.recv(100)
    assert replies == b"ab\nc\nd\n"


def test_newline_inside_a_block_or_string_is_data(server):
    payload = b"x\ny\r\n"
    with socket.create_connection(("127.0.0.1", server.port), timeout=3) as s:
        s.sendall(b'ECHO? "one\ntwo" #15' + payload + b"\n")
        reply = b""
        while not reply.endswith(payload + b"\n"):
            reply += s.recv(100)
    assert reply == b'"one\ntwo" #15' + payload + b"\n"


@pytest.mark.parametrize("chunk", [1, 3, 1000])
def test_framer_cuts_the_same_messages_whatever_the_pieces(chunk):
    stream = b'A\r\nB "q\n;""x" #210' + b"0123\n5678\n" + b"\nC\n" + b"D" * 50 + b"\nE #0\n"
    framer = MessageFramer(limit=40)
    out = []
    for i in range(0, len(stream), chunk):
        out += framer.feed(stream[i:i + chunk])
    assert out == [b"A", b'B "q\n;""x" #2100123\n5678\n', b"C", 50, b"E #0"]


def test_framer_does_not_follow_a_block_length_past_its_limit():
    """A block that claims more than the limit is not followed: its message is refused (the
    size it claimed) and ends at the next newline, so the messages after it are kept."""
    framer = MessageFramer(limit=40)
    assert framer.feed(b"CURVE #9999999999 data\n*IDN?\nECHO? \"a\nb\"\n") == [
        17 + 999_999_999, b"*IDN?", b'ECHO? "a\nb"']
    # within the limit a block is data, newlines and all; past the limit no string or block hides a newline
    assert framer.feed(b"X #15a\nb\nc\n" + b'"' + b"q" * 45 + b"\nY\n") == [b"X #15a\nb\nc", 46, b"Y"]


def test_framer_abandons_a_block_that_stops_coming():
    framer = MessageFramer(limit=1000)
    assert framer.feed(b"CURVE #3100abc") == [] and framer.in_block and framer.pending == 14
    assert framer.abandon() == 14 and not framer.in_block and framer.pending == 0
    assert framer.feed(b"\n*IDN?\n") == [b"", b"*IDN?"]


def test_a_lying_block_length_swallows_no_later_message(instrument):
    events = []
    server = SocketServer(instrument, limits=Limits(stall_timeout_s=0.3), on_event=events.append).start()
    try:
        with socket.create_connection(("127.0.0.1", server.port), timeout=3) as s:
            started = time.monotonic()
            s.sendall(b"ECHO? #9999999999 lie\n*IDN?\n")
            assert s.recv(100) == instrument.IDN + b"\n"
            assert time.monotonic() - started < 0.25  # not the stall timeout: the length was never followed
            s.sendall(b"SYST:ERR?\n")
            assert s.recv(200).startswith(b"-363,")
            s.sendall(b"ECHO? #3100short")  # a length within the limit whose bytes stop coming
            time.sleep(0.5)
            s.sendall(b"\nECHO? after\n")
            assert s.recv(100) == b"after\n"
    finally:
        server.close()
    violations = [e.detail for e in events if e.kind == EventKind.VIOLATION]
    assert violations[0] == "a program message of 1000000016 bytes (a block's claim included): allowed at most " \
                            f"{instrument.max_message_bytes}; refused"
    assert violations[1].startswith("a definite-length block stopped coming: no byte for 0.3 s; its message (16 bytes")


def test_message_over_the_limit_is_refused_and_the_connection_lives(rm, server, instrument):
    inst = open_socket(rm, server.port)
    size = instrument.max_message_bytes + 1000
    inst.write("ECHO? " + "x" * (size - 6))  # one message of `size` bytes before its terminator
    error = inst.query("SYST:ERR?")
    assert error.startswith("-363,") and f"{size} bytes" in error
    assert inst.query("ECHO? still here") == "still here"


def test_device_clear_leaves_a_usable_session(rm, server, instrument):
    inst = open_socket(rm, server.port)
    inst.write("DATA? 50000")  # the reply is never read
    time.sleep(0.2)
    inst.clear()  # pyvisa-py drops what the socket holds: a raw socket has no clear message
    assert inst.query("*IDN?") == instrument.IDN.decode()


def test_client_gone_mid_transfer_harms_nobody(rm, server, instrument, eventually):
    keep = open_socket(rm, server.port)
    for _ in range(3):
        s = socket.create_connection(("127.0.0.1", server.port))
        s.sendall(b"DATA? 20000000\n")  # 20 MB it never reads
        s.close()
        s = socket.create_connection(("127.0.0.1", server.port))
        s.sendall(b"ECHO? half a mess")  # no terminator: the message never ends
        s.close()
    assert keep.query("*IDN?") == instrument.IDN.decode()
    assert eventually(lambda: server.clients == 1 and instrument.open == 1, 10)


def test_sixteen_clients_at_once(rm, server):
    sessions = [open_socket(rm, server.port, timeout_ms=10000) for _ in range(16)]
    results = talk_at_once(sessions)
    assert server.clients == 16
    assert results == {k: [f"{k}-{i}" for i in range(25)] for k in range(16)}


def test_a_lock_taken_over_hislip_holds_the_socket_client(rm, server, instrument):
    hislip = HislipServer(instrument).start()
    try:
        holder = rm.open_resource(f"TCPIP::127.0.0.1::hislip0,{hislip.port}::INSTR")
        protocol = holder.visalib.sessions[holder.session].interface  # pyvisa-py's HiSLIP client
        assert protocol.async_lock_request(timeout=1.0) == "success"
        inst = open_socket(rm, server.port, timeout_ms=500)
        inst.write("ECHO? waited")
        with pytest.raises(VisaIOError, match="[Tt]imeout"):
            inst.read()
        assert protocol.async_lock_release() == "success"
        inst.timeout = 3000
        assert inst.read() == "waited"
    finally:
        hislip.close()


def test_close_stops_everything_promptly(rm, instrument, eventually):
    server = SocketServer(instrument).start()
    clients = [open_socket(rm, server.port, timeout_ms=500) for _ in range(4)]
    clients[0].write("WAIT? 0.3")  # one is inside the instrument as the server closes
    time.sleep(0.05)
    started = time.monotonic()
    server.close()
    assert time.monotonic() - started < 2.5
    with pytest.raises(ConnectionRefusedError):
        socket.create_connection(("127.0.0.1", server.port), timeout=1)
    assert eventually(lambda: instrument.open == 0)
    assert eventually(lambda: not any(t.name.startswith("socket-") for t in threading.enumerate()))
    with pytest.raises(VisaIOError):
        clients[1].query("*IDN?")  # the server, not the client, ended the connection


def test_framer_is_the_same_for_any_cut_of_the_stream_and_keeps_at_most_its_limit():
    from hypothesis import given, settings
    from hypothesis import strategies as st

    alphabet = st.sampled_from([b"\n", b"\r", b'"', b"'", b"#", b"0", b"1", b"2", b"9", b"A", b";", b" "])

    @settings(max_examples=300, deadline=None)
    @given(st.lists(alphabet, max_size=120).map(b"".join), st.lists(st.integers(1, 20), min_size=1))
    def same_messages(stream, cuts):
        whole = MessageFramer(limit=16).feed(stream)
        framer, pieces, i, k = MessageFramer(limit=16), [], 0, 0
        while i < len(stream):
            step = cuts[k % len(cuts)]
            pieces += framer.feed(stream[i:i + step])
            i, k = i + step, k + 1
        assert pieces == whole
        assert all(len(m) <= 16 if isinstance(m, bytes) else m > 16 for m in whole)

    same_messages()


def test_clients_over_the_maximum_are_closed_at_once(rm, instrument):
    server = SocketServer(instrument, max_clients=2).start()
    try:
        assert server.resource == f"TCPIP::127.0.0.1::{server.port}::SOCKET"
        kept = [open_socket(rm, server.port) for _ in range(2)]
        with socket.create_connection(("127.0.0.1", server.port), timeout=3) as s:
            s.sendall(b"*IDN?\n")
            try:
                got = s.recv(100)
            except ConnectionResetError:  # closed before it read what was sent
                got = b""
            assert got == b""  # closed, not left hanging
        assert [k.query("ECHO? in") for k in kept] == ["in", "in"]
    finally:
        server.close()
