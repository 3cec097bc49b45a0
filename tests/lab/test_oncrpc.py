"""ONC RPC and XDR (instruments/transports/oncrpc.py): bytes as RFC 4506 and RFC 5531 give
them, the replies a server owes to calls it cannot run, and record marking that never
allocates a fragment over its bound. Cross-checked with pyvisa-py's RPC packer (an
independent implementation of the same RFCs)."""
import contextlib
import socket
import struct
import threading
import time

import pytest
from pyvisa_py.protocols import rpc as pyvisa_rpc

from instruments.transports import oncrpc
from instruments.transports.tcp import TcpService

PROG = 0x2000_0001  # a user-defined program number (RFC 5531 7.3: 0x20000000-0x3fffffff)


def test_xdr_items_are_big_endian_words_and_opaque_data_is_padded_to_four():
    w = oncrpc.XdrWriter().uint(0xDEADBEEF).int(-2).bool(True).opaque(b"abcde").string(b"")
    assert bytes(w) == (b"\xde\xad\xbe\xef" b"\xff\xff\xff\xfe" b"\0\0\0\x01"
                        b"\0\0\0\x05abcde\0\0\0" b"\0\0\0\0")
    r = oncrpc.XdrReader(bytes(w))
    assert (r.uint(), r.int(), r.bool(), r.opaque(), r.string()) == (0xDEADBEEF, -2, True, b"abcde", b"")
    r.done()


@pytest.mark.parametrize("data", [b"", b"a", b"ab", b"abc", b"abcd", bytes(range(256)) * 3])
def test_opaque_matches_pyvisa_py_packer_both_ways(data):
    theirs = pyvisa_rpc.Packer()
    theirs.pack_uint(7)
    theirs.pack_opaque(data)
    ours = bytes(oncrpc.XdrWriter().uint(7).opaque(data))
    assert ours == theirs.get_buffer()
    back = pyvisa_rpc.Unpacker(ours)
    assert (back.unpack_uint(), back.unpack_opaque()) == (7, data)


def test_reader_refuses_short_data_a_length_over_its_bound_a_bad_bool_and_leftovers():
    with pytest.raises(oncrpc.XdrError, match="2 bytes early"):
        oncrpc.XdrReader(b"\0\0").uint()
    huge = struct.pack(">I", 0xFFFF_FFF0) + b"abcd"  # claims 4 GiB: refused before reading
    with pytest.raises(oncrpc.XdrError, match="at most 64 bytes"):
        oncrpc.XdrReader(huge).opaque(64)
    with pytest.raises(oncrpc.XdrError, match="ends .* early"):
        oncrpc.XdrReader(huge).opaque()
    with pytest.raises(oncrpc.XdrError, match="allowed 0 or 1"):
        oncrpc.XdrReader(b"\0\0\0\x02").bool()
    r = oncrpc.XdrReader(b"\0\0\0\x01\0\0\0\x02")
    r.uint()
    with pytest.raises(oncrpc.XdrError, match="4 bytes after"):
        r.done()


def test_record_marking_joins_fragments_and_refuses_an_oversize_one_before_reading_it():
    a, b = socket.socketpair()
    a.settimeout(2.0)
    b.settimeout(2.0)
    with a, b:
        oncrpc.write_record(a, b"hello")
        assert oncrpc.read_record(b, 100) == b"hello"
        a.sendall(struct.pack(">I", 3) + b"abc" + struct.pack(">I", 0x8000_0002) + b"de")
        assert oncrpc.read_record(b, 100) == b"abcde"
        # a header claiming 2 GiB with no body behind it: refused at the header (reading the
        # body would time out instead, a different error)
        a.sendall(struct.pack(">I", 0xFFFF_FFFF))
        with pytest.raises(oncrpc.RecordTooLarge, match="at most 1000"):
            oncrpc.read_record(b, 1000)
        # fragments that are each small but add up past the bound are refused too
        a.sendall((struct.pack(">I", 600) + b"x" * 600) * 2)
        with pytest.raises(oncrpc.RecordTooLarge):
            oncrpc.read_record(b, 1000)


def _call(xid, prog, vers, proc, args=b"", rpcvers=2):
    head = (oncrpc.XdrWriter().uint(xid).uint(0).uint(rpcvers).uint(prog).uint(vers).uint(proc)
            .uint(0).opaque(b"").uint(0).opaque(b""))
    return bytes(head) + args


def _add(r):
    a, b = r.int(), r.int()
    r.done()
    return bytes(oncrpc.XdrWriter().int(a + b))


PROGRAMS = {PROG: oncrpc.Program(PROG, 2, 3, {1: _add})}


def _reply_status(reply):
    r = oncrpc.XdrReader(reply)
    xid, kind, stat = r.uint(), r.uint(), r.uint()
    assert kind == 1
    return xid, stat, r


def test_server_answers_success_and_each_rpc_failure_as_rfc_5531_gives_it():
    args = bytes(oncrpc.XdrWriter().int(40).int(2))
    xid, stat, r = _reply_status(oncrpc.answer(_call(9, PROG, 2, 1, args), PROGRAMS))
    r.uint(), r.opaque()  # verifier
    assert (xid, stat, r.uint(), r.int()) == (9, oncrpc.MSG_ACCEPTED, oncrpc.SUCCESS, 42)

    def accept_status(record):
        _, stat, r = _reply_status(oncrpc.answer(record, PROGRAMS))
        assert stat == oncrpc.MSG_ACCEPTED
        r.uint(), r.opaque()
        return r.uint(), r

    assert accept_status(_call(1, PROG + 1, 2, 1, args))[0] == oncrpc.PROG_UNAVAIL
    status, r = accept_status(_call(1, PROG, 4, 1, args))
    assert (status, r.uint(), r.uint()) == (oncrpc.PROG_MISMATCH, 2, 3)
    assert accept_status(_call(1, PROG, 2, 7, args))[0] == oncrpc.PROC_UNAVAIL
    assert accept_status(_call(1, PROG, 2, 1, args[:6]))[0] == oncrpc.GARBAGE_ARGS
    assert accept_status(_call(1, PROG, 2, 1, args + b"\0\0\0\0"))[0] == oncrpc.GARBAGE_ARGS
    assert accept_status(_call(1, PROG, 3, 0))[0] == oncrpc.SUCCESS  # NULL of every program

    _, stat, r = _reply_status(oncrpc.answer(_call(5, PROG, 2, 1, args, rpcvers=3), PROGRAMS))
    assert (stat, r.uint(), r.uint(), r.uint()) == (oncrpc.MSG_DENIED, oncrpc.RPC_MISMATCH, 2, 2)
    # not a call (a reply, or too short for a header): nothing to answer
    assert oncrpc.answer(bytes(oncrpc.XdrWriter().uint(1).uint(1)), PROGRAMS) is None
    assert oncrpc.answer(b"\x01\x02", PROGRAMS) is None


def test_a_served_connection_answers_in_order_and_is_closed_on_an_oversize_record():
    events = []
    service = TcpService(lambda conn, peer: oncrpc.serve_connection(conn, PROGRAMS, 512), name="rpc",
                         on_event=events.append).start()
    try:
        client = oncrpc.RpcClient("127.0.0.1", service.port, PROG, 2)
        for k in range(5):
            assert client.call(1, bytes(oncrpc.XdrWriter().int(k).int(k))).int() == 2 * k
        with pytest.raises(oncrpc.RpcError, match="PROC_UNAVAIL"):
            client.call(3)
        client.close()
        raw = socket.create_connection(("127.0.0.1", service.port), timeout=5.0)
        oncrpc.write_record(raw, _call(1, PROG, 2, 1, b"\0" * 600))  # over the 512-byte bound
        # closed unanswered (a reset when the unread rest of the record was dropped)
        with contextlib.suppress(ConnectionResetError):
            assert raw.recv(100) == b""
        raw.close()
        # the service still answers a new client
        again = oncrpc.RpcClient("127.0.0.1", service.port, PROG, 2)
        assert again.call(1, bytes(oncrpc.XdrWriter().int(1).int(2))).int() == 3
        again.close()
    finally:
        service.close()
    # the violation is told, with the connection and its end
    assert [e.kind.value for e in events if e.kind.value != "connected"].count("protocol violation") == 1
    (violation,) = [e.line() for e in events if e.kind.value == "protocol violation"]
    assert violation.startswith("rpc 127.0.0.1:") and violation.endswith(
        "protocol violation: record of at least 640 bytes: allowed at most 512")  # with its call header
    assert any(e.line().endswith("disconnected: after the protocol violation") for e in events)


def test_a_client_that_closes_mid_record_ends_only_its_own_connection():
    service = TcpService(lambda conn, peer: oncrpc.serve_connection(conn, PROGRAMS, 512)).start()
    try:
        s = socket.create_connection(("127.0.0.1", service.port))
        s.sendall(struct.pack(">I", 0x8000_0000 | 100) + b"x" * 10)  # 90 bytes short
        s.close()
        done = threading.Event()

        def other():
            c = oncrpc.RpcClient("127.0.0.1", service.port, PROG, 2)
            assert c.call(1, bytes(oncrpc.XdrWriter().int(2).int(2))).int() == 4
            c.close()
            done.set()

        t = threading.Thread(target=other)
        t.start()
        t.join(5)
        assert done.is_set()
        for _ in range(50):
            if service.clients == 0:
                break
            time.sleep(0.05)
        assert service.clients == 0
    finally:
        service.close()
