"""CURVEStream? (4 Series MSO Programmer Manual): after the query each read a client makes
gets the next acquisition's curve, in the DATa format set, a new shot at the next seed;
another command or query, or a device clear, ends the stream, and the next query gets its
own answer. Real clients (pyvisa with pyvisa-py) over the raw socket, HiSLIP and VXI-11,
against the emulated 4 Series on the synthetic shot source (lab_scope.py), whose records
at a seed the test recomputes; the TDS2000's and MDO3000's manuals have no such query."""
import logging
import socket
import time

import numpy as np
import pytest
from pyvisa_py.protocols import vxi11 as v
from pyvisa_py.tcpip import Vxi11CoreClient

from instruments.transports.hislip import HislipServer
from instruments.transports.socket import SocketServer
from instruments.transports.vxi11 import Vxi11Server
from instruments.virtual_scope.instrument import VirtualScope
from lab.lab_scope import PulseSource, ask, scene_scope, velocity_only
from rig.lab.serve_log import LoggedInstrument, Refusals

POINTS = 10_000
SETUP = "*CLS;:HEADER OFF;:DATA:SOURCE CH1;:DATA:ENCDG RIBINARY;:DATA:WIDTH 1;:DATA:START 1;:DATA:STOP 10000"


class Lines(logging.Handler):
    def __init__(self):
        super().__init__()
        self.lines = []

    def emit(self, record):
        self.lines.append(record.getMessage())


@pytest.fixture(scope="module")
def served():
    """An emulated MSO44 (synthetic shots, first seed 50) on a raw socket, HiSLIP and VXI-11,
    each session logged as ``rig serve scope --log`` logs it; (scope, source, servers, log lines)."""
    scene = scene_scope(POINTS)
    source = PulseSource(scene)
    scope = VirtualScope(scene, source, personality_name="mso4", validate=velocity_only, seed=50)
    log = logging.getLogger("test.curvestream")
    log.propagate, lines = False, Lines()
    log.setLevel(logging.INFO)
    log.addHandler(lines)
    refusals = Refusals(scope, log)
    servers = {"SOCKET": SocketServer(LoggedInstrument(scope, refusals, "raw socket")).start(),
               "hislip": HislipServer(LoggedInstrument(scope, refusals, "HiSLIP")).start(),
               "VXI-11": Vxi11Server(LoggedInstrument(scope, refusals, "VXI-11"), "127.0.0.1", 0).start()}
    yield scope, source, servers, lines.lines
    for server in servers.values():
        server.close()
    scope.close()
    log.removeHandler(lines)


def resource(servers, kind):
    server = servers[kind]
    return server.resource_at("127.0.0.1", by_port=True) if kind == "VXI-11" else server.resource


def block_codes(raw: bytes) -> np.ndarray:
    """The int8 codes of one ``#<n><length><bytes>\\n`` block, checked whole."""
    assert raw[:1] == b"#" and raw.endswith(b"\n")
    digits = int(raw[1:2])
    length = int(raw[2:2 + digits])
    assert len(raw) == 2 + digits + length + 1
    return np.frombuffer(raw[2 + digits:2 + digits + length], ">i1")


def read_block(inst, kind, k: int) -> np.ndarray:
    """Block k of a stream as the client reads it."""
    if kind == "SOCKET":  # a socket has no END: the block's own length says where it stops
        return inst.read_binary_values(datatype="b", is_big_endian=True, container=np.array)
    if kind == "hislip" and k:  # pyvisa-py's HiSLIP read ends at the first DataEnd until it sends again:
        from pyvisa_py.protocols import hislip  # the next ones off its synchronous channel, its own parser

        client = inst.visalib.sessions[inst.session].interface
        header = hislip.RxHeader(client._sync)
        assert header.msg_type == "DataEnd" and header.message_parameter == client.last_message_id
        return block_codes(hislip.receive_exact(client._sync, header.payload_length))
    return block_codes(inst.read_raw())  # VXI-11 and HiSLIP: one response, up to its END


def settled(source, quiet_s=0.3, timeout_s=10.0) -> int:
    """The number of shots once no new one has come for ``quiet_s``."""
    end, n = time.monotonic() + timeout_s, -1
    while time.monotonic() < end:
        n = len(source.calls)
        time.sleep(quiet_s)
        if len(source.calls) == n:
            return n
    raise AssertionError("shots kept coming")


@pytest.mark.parametrize("kind", ["SOCKET", "hislip", "VXI-11"])
def test_three_streamed_blocks_are_three_shots_at_the_next_seeds_and_a_query_after_gets_its_answer(served, rm,
                                                                                                  kind):
    scope, source, servers, _ = served
    inst = rm.open_resource(resource(servers, kind), timeout=20_000)
    if kind == "SOCKET":
        inst.read_termination = inst.write_termination = "\n"
    try:
        inst.write(SETUP)
        seed, before = int(inst.query("RIG:SEED?")), len(source.calls)
        overrides = scope.overrides()
        inst.write("CURVESTREAM?")
        blocks = [read_block(inst, kind, k) for k in range(3)]
        inst.write("*CLS")  # any command ends the stream (the manual)
        if kind == "SOCKET":
            inst.clear()  # a raw socket has no device clear: VISA drains what the stream had sent
        assert inst.query("*IDN?").startswith("TEKTRONIX,MSO44")
        fired = settled(source)
        shots = source.calls[before:fired]
        assert [s for _, s in shots] == list(range(seed, seed + len(shots)))  # the seed sequence, no gap
        assert 3 <= len(shots) <= (3 if kind == "VXI-11" else 3 + 64)  # VXI-11: a shot per read, no more
        for k, codes in enumerate(blocks):
            assert shots[k] == (overrides, seed + k)
            expected = source.record(overrides, seed + k)["CH1"].codes
            assert codes.size == POINTS and np.array_equal(codes, expected), k  # code for code
        assert len({codes.tobytes() for codes in blocks}) == 3  # three acquisitions, not one sent thrice
        assert int(inst.query("RIG:SEED?")) == seed + len(shots)  # the sequence goes on after the stream
        assert scope.stream is None and len(source.calls) == fired  # out of streaming mode: no more shots
    finally:
        inst.close()


def test_a_device_clear_ends_the_stream_and_the_next_query_is_answered(served, rm):
    scope, source, servers, lines = served
    inst = rm.open_resource(resource(servers, "hislip"), timeout=20_000)
    try:
        inst.write(SETUP + ";:HEADER ON")
        inst.write("CURVESTREAM?")
        raw = inst.read_raw()
        assert raw.startswith(b":CURVESTREAM #510000") and block_codes(raw[len(":CURVESTREAM "):]).size == POINTS
        inst.clear()
        fired = settled(source)
        assert scope.stream is None and inst.query("HEADER OFF;*ESR?").strip() == "0"  # no error: an intended way out
        assert len(source.calls) == fired
    finally:
        inst.close()
    assert any("curve stream to HiSLIP" in line and "ended after" in line and "a device clear" in line
               for line in lines)


def test_a_client_that_never_reads_piles_nothing_up(served, eventually):
    """Raw socket: the next record is made once the last has left the server, so a client
    that reads nothing stops the acquisitions when its receive buffer is full. VXI-11: a
    record is made only for a read, none here."""
    scope, source, servers, _ = served
    with socket.create_connection(("127.0.0.1", servers["SOCKET"].port)) as sock:
        sock.sendall(SETUP.encode() + b"\nCURVESTREAM?\n")
        before = len(source.calls)
        held = settled(source, quiet_s=0.5)
        assert 1 <= held - before <= 64  # 10 kB blocks: what a loopback connection's buffers take
        assert scope.stream is not None  # still streaming, waiting for the client
        sock.sendall(b"*CLS\n")
        assert eventually(lambda: scope.stream is None, timeout_s=0.2)
    client = Vxi11CoreClient("127.0.0.1", servers["VXI-11"].port)  # pyvisa-py's RPC client: a write, no read
    error, link, _, _ = client.create_link(1, 0, 0, "inst0")
    assert error == 0
    before = len(source.calls)
    assert client.device_write(link, 2000, 0, v.OP_FLAG_END, b"CURVESTREAM?") == (0, 12)
    time.sleep(0.2)  # a record, were one asked for, would be made in milliseconds (the kernels ran above)
    assert scope.stream is not None and len(source.calls) == before  # nothing made while nothing is read
    client.destroy_link(link)
    client.close()


def test_the_stream_is_the_4_series_alone_and_one_at_a_time(make_scope):
    for personality in ("tds2000", "mdo3000"):  # their manuals have no CURVEStream?
        _scope, s, _ = make_scope(personality)
        assert s.handle(b"CURVESTREAM?") == b"" and ask(s, "EVENT?") == "113"
    scope, s, source = make_scope("mso4")
    other = scope.open_session("other")
    assert s.handle(b"CURVESTREAM?") == b"" and scope.stream is not None
    assert other.handle(b"CURVESTREAM?") == b"" and ask(other, "EVENT?") == "200"  # one stream at a time
    assert other.next_reply(0.0) is None and source.calls == []  # asked for nothing yet
    assert s.next_reply(0.0) == b"" and s.next_reply(30.0).startswith(b"#510000")  # the first record, asked for
    assert [seed for _, seed in source.calls] == [0]
    assert s.handle(b"*CLS") == b"" and scope.stream is None and s.next_reply(0.0) is None  # a command ends it
