"""The HiSLIP server (instruments/transports/hislip*.py) through pyvisa + pyvisa-py's
``TCPIP::host::hislip0,port::INSTR`` resource, against the echo instrument.

pyvisa-py's HiSLIP session has no viLock or viAssertTrigger, so locks and triggers go through
its HiSLIP protocol client (``pyvisa_py.protocols.hislip.Instrument``, the session's
``interface``); bad headers and oversize messages through its message functions on a socket."""
import socket
import struct
import threading
import time

import pytest
from pyvisa.errors import VisaIOError

from instruments.transports.hislip import HislipServer
from instruments.transports.wire import EventKind, Limits
from lab.many_clients import talk_at_once


@pytest.fixture
def server(instrument):
    srv = HislipServer(instrument).start()
    yield srv
    srv.close()


def open_hislip(rm, port, timeout_ms=3000):
    return rm.open_resource(f"TCPIP::127.0.0.1::hislip0,{port}::INSTR", read_termination="\n",
                            write_termination="\n", timeout=timeout_ms)


def protocol(inst):
    """pyvisa-py's HiSLIP client behind a pyvisa resource."""
    return inst.visalib.sessions[inst.session].interface


def hislip_module():
    from pyvisa_py.protocols import hislip
    return hislip


def test_write_and_query(rm, server, instrument):
    inst = open_hislip(rm, server.port)
    assert inst.query("*IDN?") == instrument.IDN.decode()
    inst.write("NOT:A:COMMAND")
    assert inst.query("ECHO? hello world") == "hello world"
    assert inst.query("SYST:ERR?").startswith("-113,")
    assert protocol(inst).max_msg_size == instrument.max_message_bytes  # AsyncMaximumMessageSize


def test_messages_without_a_terminator_end_at_dataend(rm, server, instrument):
    inst = rm.open_resource(f"TCPIP::127.0.0.1::hislip0,{server.port}::INSTR", write_termination="",
                            read_termination="")  # as scripts that set no termination write
    inst.write("ECHO? bare")
    assert inst.read_raw() == b"bare\n"


def test_one_megabyte_reply_arrives_whole(rm, server, instrument):
    inst = open_hislip(rm, server.port, timeout_ms=10000)
    data = inst.query_binary_values("DATA? 1000000", datatype="B", container=bytes)
    assert data == instrument.pattern(1_000_000)
    assert inst.query("*IDN?") == instrument.IDN.decode()


def test_reply_is_cut_to_the_clients_maximum_message_size(rm, server, instrument):
    inst = open_hislip(rm, server.port)
    client = protocol(inst)
    client.async_maximum_message_size(1024)  # this client takes messages of 1 KiB at most
    hislip = hislip_module()
    inst.write("DATA? 100000")
    parts = []
    while not parts or parts[-1][0] != "DataEnd":
        header = hislip.RxHeader(client._sync)
        parts.append((header.msg_type, hislip.receive_exact(client._sync, header.payload_length)))
    body = b"".join(p for _, p in parts)
    assert len(parts) > 98 and all(len(p) <= 1024 for _, p in parts)
    assert body == b"#6100000" + instrument.pattern(100000) + b"\n"


def test_many_queries_in_a_row(rm, server):
    inst = open_hislip(rm, server.port)
    assert [inst.query(f"ECHO? {k}") for k in range(200)] == [str(k) for k in range(200)]


def test_exclusive_lock_holds_others_out_until_released(rm, server, instrument):
    a, b = open_hislip(rm, server.port), open_hislip(rm, server.port, timeout_ms=500)
    la, lb = protocol(a), protocol(b)
    assert la.async_lock_request(timeout=1.0) == "success"
    assert la.async_lock_info() == 1  # exclusive lock granted
    started = time.monotonic()
    assert lb.async_lock_request(timeout=0.3) == "failure"
    assert 0.25 < time.monotonic() - started < 2.0  # it waited its timeout, not less, not forever
    b.write("ECHO? held")
    b.timeout = 200  # unlocked, the echo comes within milliseconds
    with pytest.raises(VisaIOError, match="[Tt]imeout"):
        b.read()  # the message waits while a holds the lock
    b.timeout = 500
    assert a.query("ECHO? holder") == "holder"  # the holder goes on
    assert la.async_lock_release() == "success"
    assert b.read() == "held"
    assert lb.async_lock_request(timeout=1.0) == "success"
    assert instrument.lock.state().holders == 1


def test_shared_lock_is_shared_by_its_string_only(rm, server, instrument):
    a, b, c = (open_hislip(rm, server.port) for _ in range(3))
    assert protocol(a).async_lock_request(timeout=0.5, lock_string="grp") == "success"
    assert protocol(b).async_lock_request(timeout=0.5, lock_string="grp") == "success"
    assert protocol(c).async_lock_request(timeout=0.2, lock_string="other") == "failure"
    assert protocol(c).async_lock_request(timeout=0.2) == "failure"  # exclusive
    state = instrument.lock.state()
    assert (state.exclusive, state.holders) == (False, 2)
    assert protocol(a).async_lock_info() == 0  # held, but not exclusively
    assert c.query("ECHO? shared locks let others talk") == "shared locks let others talk"
    assert protocol(a).async_lock_release() == "success shared"
    assert protocol(a).async_lock_release() == "error"  # nothing held any more
    assert protocol(b).async_lock_release() == "success shared"
    assert protocol(c).async_lock_request(timeout=0.5) == "success"


def test_lock_of_a_client_that_goes_is_released(rm, server, instrument, eventually):
    a, b = open_hislip(rm, server.port), open_hislip(rm, server.port)
    assert protocol(a).async_lock_request(timeout=0.5) == "success"
    a.close()
    assert eventually(lambda: instrument.lock.state().holders == 0)
    assert protocol(b).async_lock_request(timeout=0.5) == "success"


def test_device_clear_ends_a_wait_and_drops_its_reply(rm, server, instrument):
    inst = open_hislip(rm, server.port, timeout_ms=5000)
    inst.write("WAIT? 30")  # the instrument waits (as in *OPC?) when the clear comes
    time.sleep(0.1)
    started = time.monotonic()
    inst.clear()
    assert time.monotonic() - started < 5.0  # not the 30 s wait (pyvisa-py itself pauses 0.1 s)
    assert instrument.clears == 1
    assert inst.query("*IDN?") == instrument.IDN.decode()  # no DONE before it
    assert inst.query("COUNT? CLEAR") == "1"


def test_read_stb_reports_an_undelivered_reply_and_errors(rm, server, instrument, eventually):
    inst = open_hislip(rm, server.port)
    assert inst.read_stb() == 0
    inst.write("ECHO? waiting")
    assert eventually(lambda: inst.read_stb() == 0x10)  # MAV: a reply is waiting for the client
    assert inst.read() == "waiting"
    assert inst.read_stb() == 0  # it was taken (RMT-delivered)
    inst.write("BAD:HEADER")  # the channels are two connections: the status may come first
    assert eventually(lambda: inst.read_stb() == 0x04)  # the error queue is not empty
    assert inst.query("SYST:ERR?").startswith("-113,")
    assert inst.read_stb() == 0


def test_trigger_message_reaches_the_instrument(rm, server, instrument):
    inst = open_hislip(rm, server.port)
    protocol(inst).trigger()
    protocol(inst).trigger()
    assert inst.query("COUNT? TRG") == "2"


def test_new_message_before_the_last_reply_was_read_interrupts_it(rm, server, instrument):
    inst = open_hislip(rm, server.port)
    inst.write("ECHO? never read")
    time.sleep(0.1)
    assert inst.query("ECHO? second") == "second"  # the first reply is discarded by its id
    hislip = hislip_module()
    interrupted = hislip.AsyncInterrupted(protocol(inst)._async)
    assert interrupted.message_id == protocol(inst).last_message_id  # the message that interrupted


def test_message_over_the_limit_in_parts_is_dropped_and_reported(rm, server, instrument):
    inst = open_hislip(rm, server.port)
    size = instrument.max_message_bytes + 5000  # pyvisa-py sends it as Data + DataEnd
    inst.write_raw(b"ECHO? " + b"x" * (size - 6))
    error = inst.query("SYST:ERR?")
    assert error.startswith("-363,") and f"{size} bytes" in error
    assert inst.query("ECHO? alive") == "alive"


def test_one_data_message_over_the_maximum_gets_an_error(rm, server, instrument):
    inst = open_hislip(rm, server.port)
    client, hislip = protocol(inst), hislip_module()
    size = instrument.max_message_bytes + 1
    hislip.send_msg(client._sync, "DataEnd", 0, 0xFFFF_FF00, b"E" * size)
    error = hislip.Error(client._sync)
    assert error.error_code == "Message too large" and str(instrument.max_message_bytes).encode() in error.error_message
    assert inst.query("SYST:ERR?").startswith("-363,")
    assert inst.query("ECHO? alive") == "alive"


def test_bad_prologue_gets_a_fatal_error_and_the_server_lives(rm, server, instrument):
    hislip = hislip_module()
    with socket.create_connection(("127.0.0.1", server.port), timeout=3) as s:
        s.sendall(b"XX" + bytes(14))
        fatal = hislip.FatalError(s)
        assert fatal.error_code == "Poorly formed message header"
        assert s.recv(10) == b""  # and the connection is closed
    with socket.create_connection(("127.0.0.1", server.port), timeout=3) as s:
        s.sendall(struct.pack("!2sBBIQ", b"HS", 6, 0, 0, 0))  # Data before Initialize
        assert hislip.FatalError(s).error_code == "Invalid Initialization sequence"
    inst = open_hislip(rm, server.port)
    assert inst.query("*IDN?") == instrument.IDN.decode()


def test_unknown_sub_address_is_refused(rm, server):
    from pyvisa.errors import VisaIOError as Refused
    with pytest.raises(Refused):
        rm.open_resource(f"TCPIP::127.0.0.1::hislip7,{server.port}::INSTR")
    assert server.sessions == 0


def test_unknown_message_type_gets_an_error_and_the_session_goes_on(rm, server):
    inst = open_hislip(rm, server.port)
    client, hislip = protocol(inst), hislip_module()
    hislip.send_msg(client._async, "GetDescriptors", 0, 0)  # HiSLIP 2.0 only; not served
    assert hislip.Error(client._async).error_code == "Unrecognized Message Type"
    assert inst.read_stb() == 0
    assert inst.query("ECHO? on") == "on"


def test_client_gone_mid_transfer_harms_nobody(rm, server, instrument, eventually):
    keep = open_hislip(rm, server.port)
    hislip = hislip_module()
    for _ in range(3):
        gone = hislip.Instrument("127.0.0.1", port=server.port)
        gone.send(b"DATA? 20000000")  # 20 MB it never reads
        gone.close()
        half = hislip.Instrument("127.0.0.1", port=server.port)
        half._sync.sendall(struct.pack("!2sBBIQ", b"HS", 7, 0, 0xFFFF_FF00, 1000) + b"ECHO? ")
        half.close()  # 994 bytes of its message never come
    assert keep.query("*IDN?") == instrument.IDN.decode()
    assert eventually(lambda: server.sessions == 1 and instrument.open == 1, 15)


def test_sixteen_clients_at_once(rm, server):
    sessions = [open_hislip(rm, server.port, timeout_ms=10000) for _ in range(16)]
    results = talk_at_once(sessions)
    assert server.sessions == 16
    assert results == {k: [f"{k}-{i}" for i in range(25)] for k in range(16)}


def test_close_stops_everything_promptly(rm, instrument, eventually):
    server = HislipServer(instrument).start()
    holder, waiter = open_hislip(rm, server.port), open_hislip(rm, server.port, timeout_ms=60000)
    assert protocol(holder).async_lock_request(timeout=0.5) == "success"
    outcome = []

    def wait_for_lock():
        try:
            outcome.append(protocol(waiter).async_lock_request(timeout=30))
        except (OSError, RuntimeError) as e:  # pyvisa-py's word for a connection the server dropped
            outcome.append(e)

    waiting = threading.Thread(target=wait_for_lock, daemon=True)
    waiting.start()  # a lock request that would wait 30 s
    time.sleep(0.2)
    started = time.monotonic()
    server.close()
    assert time.monotonic() - started < 2.5
    with pytest.raises(ConnectionRefusedError):
        socket.create_connection(("127.0.0.1", server.port), timeout=1)
    assert eventually(lambda: instrument.open == 0 and instrument.lock.state().holders == 0)
    assert eventually(lambda: not any(t.name.startswith("hislip-") for t in threading.enumerate()))
    waiting.join(2)
    assert not waiting.is_alive() and outcome and outcome[0] != "success"  # dropped, not granted


def initialize(conn, version=(1, 0), sub_address=b"hislip0"):
    """Send an Initialize as IVI-6.1 lays it out: version bytes and vendor id in the parameter."""
    conn.sendall(struct.pack("!2sBBBB2sQ", b"HS", 0, 0, *version, b"zz", len(sub_address)) + sub_address)


@pytest.mark.parametrize("asked, granted", [((1, 0), 0x0100), ((1, 1), 0x0101), ((2, 0), 0x0200), ((3, 0), 0x0200)])
def test_version_is_the_lower_of_the_clients_and_2_0(server, asked, granted):
    hislip = hislip_module()
    with socket.create_connection(("127.0.0.1", server.port), timeout=3) as s:
        initialize(s, asked)
        reply = hislip.InitializeResponse(s)
        assert (reply.version, reply.overlap) == (granted, False)  # synchronized mode
        assert reply.session_id >= 1


def test_async_channel_pairs_by_session_id_only(server):
    hislip = hislip_module()
    with socket.create_connection(("127.0.0.1", server.port), timeout=3) as sync:
        initialize(sync)
        session_id = hislip.InitializeResponse(sync).session_id
        sync.sendall(struct.pack("!2sBBIQ", b"HS", 7, 0, 0, 6) + b"*IDN?\n")  # Data before the async channel
        assert hislip.FatalError(sync).error_code == "Attempt to use connection without both channels established"
    for wrong in (session_id + 1000, 0):
        with socket.create_connection(("127.0.0.1", server.port), timeout=3) as s:
            hislip.send_msg(s, "AsyncInitialize", 0, wrong)
            assert hislip.FatalError(s).error_code == "Invalid Initialization sequence"


def test_async_initialize_response_names_the_vendor(rm, server):
    inst = open_hislip(rm, server.port)
    assert protocol(inst)._async_init.vendor_id == (b"\x00\x00TK",)


def test_remote_local_control_and_bad_control_codes(rm, server):
    inst = open_hislip(rm, server.port)
    client, hislip = protocol(inst), hislip_module()
    for request in ("enableRemote", "disableAndGTL", "justGTL"):
        client.async_remote_local_control(request)  # answered with AsyncRemoteLocalResponse
    hislip.send_msg(client._async, "AsyncRemoteLocalControl", 9, 0)
    assert hislip.Error(client._async).error_code == "Unrecognized control code"
    hislip.send_msg(client._async, "AsyncLock", 7, 0)
    assert hislip.Error(client._async).error_code == "Unrecognized control code"
    assert client.async_lock_request(timeout=0.1, lock_string="k" * 300) == "error"  # over 256 bytes
    assert inst.query("ECHO? fine") == "fine"


def test_random_bytes_never_take_the_server_down(rm, instrument):
    from hypothesis import HealthCheck, given, settings
    from hypothesis import strategies as st

    server = HislipServer(instrument).start()
    try:
        inst = open_hislip(rm, server.port)
        hislip = hislip_module()

        @settings(max_examples=60, deadline=None, suppress_health_check=list(HealthCheck))
        @given(st.binary(max_size=64), st.booleans(), st.integers(0, 255))
        def survives(garbage, headed, kind):
            with socket.create_connection(("127.0.0.1", server.port), timeout=3) as s:
                if headed:  # a well-formed header of any type, then garbage
                    s.sendall(struct.pack("!2sBBIQ", b"HS", kind, 0, 0, len(garbage)))
                s.sendall(garbage)
            assert inst.query("ECHO? alive") == "alive"

        survives()
        assert hislip.Instrument("127.0.0.1", port=server.port).async_status_query() == 0
    finally:
        server.close()


def test_sessions_over_the_maximum_are_refused_with_a_reason(rm, instrument, eventually):
    server = HislipServer(instrument, max_sessions=2).start()
    try:
        assert server.resource == f"TCPIP::127.0.0.1::hislip0,{server.port}::INSTR"
        first, second = open_hislip(rm, server.port), open_hislip(rm, server.port)
        with socket.create_connection(("127.0.0.1", server.port), timeout=3) as s:
            initialize(s)
            fatal = hislip_module().FatalError(s)
            assert fatal.error_code == "Server refused connection due to maximum number of clients exceeded"
            assert b"2" in fatal.error_message
        with pytest.raises(VisaIOError):
            rm.open_resource(server.resource)
        first.close()
        assert eventually(lambda: server.sessions == 1)
        third = open_hislip(rm, server.port)
        assert third.query("*IDN?") == second.query("*IDN?") == instrument.IDN.decode()
    finally:
        server.close()


def test_half_open_sessions_make_room_for_a_client_and_are_closed_soon(rm, instrument, eventually):
    """Sessions whose async channel never comes (an Initialize alone) do not lock the server
    out: a new client takes the oldest one's place at once, and each is closed after the
    half-open timeout, as is a connection that never says anything."""
    events = []
    server = HislipServer(instrument, max_sessions=2, limits=Limits(half_open_timeout_s=0.5),
                          on_event=events.append).start()
    half = [socket.create_connection(("127.0.0.1", server.port), timeout=3) for _ in range(3)]
    mute = socket.create_connection(("127.0.0.1", server.port), timeout=3)
    try:
        for s in half:
            initialize(s)
            assert hislip_module().InitializeResponse(s).session_id >= 1  # each evicts the oldest past two
        assert server.sessions == 2
        inst = open_hislip(rm, server.port)  # a third Initialize: a half-open session makes room
        assert inst.query("*IDN?") == instrument.IDN.decode()
        assert eventually(lambda: server.sessions == 1, 3)  # the half-open ones closed after 0.5 s
        assert mute.recv(10) == b""
        assert inst.query("ECHO? stays") == "stays"
    finally:
        for s in [*half, mute]:
            s.close()
        server.close()
    ends = [e.detail for e in events if e.kind == EventKind.DISCONNECTED]
    assert sum("evicted: a half-open session (no AsyncInitialize)" in d for d in ends) == 2
    assert "half-open: no AsyncInitialize (the session's second connection) within 0.5 s" in ends
    assert "half-open: no Initialize or AsyncInitialize within 0.5 s" in ends
