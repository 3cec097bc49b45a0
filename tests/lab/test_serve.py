"""``rig serve scope`` end to end: the command a lab runs, real VISA clients (pyvisa with
pyvisa-py) on each transport, the records compared bit for bit with ``rig shot`` at the
same settings and seed, SIGTERM ending it cleanly, bad input refused in one line."""
import socket
from pathlib import Path

import numpy as np
import pytest

pyvisa = pytest.importorskip("pyvisa")

from instruments.formats import read_waveforms
from lab.served import Served, open_scope

SCENE = "ptfe52_magnetic"
FIRST_SEED = 11


@pytest.fixture(scope="module")
def served(port111):
    s = Served(SCENE, "--port", "0", "--hislip", "0", "--vxi11", "--seed", str(FIRST_SEED))
    yield s
    if s.proc.poll() is None:
        s.stop()


def shot_codes(rm, resource: str, channel: str = "CH1") -> tuple:
    """One single-sequence shot through ``resource``: (codes of ``channel``, the overrides it
    was fired with, its seed)."""
    scope = open_scope(rm, resource)
    try:
        scope.write("*CLS;:HEADER OFF;:ACQUIRE:STOPAFTER SEQUENCE")
        overrides = scope.query("RIG:OVERRIDES?").strip().strip('"')
        seed = int(scope.query("RIG:SEED?"))
        scope.write("ACQUIRE:STATE ON")
        assert scope.query("*OPC?").strip() == "1"
        assert scope.query("ACQUIRE:STATE?").strip() == "0"
        scope.write(f"DATA:SOURCE {channel};:DATA:ENCDG RIBINARY;:DATA:WIDTH 1;:DATA:START 1;:DATA:STOP 1000000")
        codes = scope.query_binary_values("CURVE?", datatype="b", container=np.array, is_big_endian=True)
        assert scope.query("*ESR?").strip() in ("0", "1")  # no error bit: only OPC may be set
        return codes, [o for o in overrides.split(",") if o], seed
    finally:
        scope.close()


def rig_shot_codes(tmp_path: Path, overrides: list, seed: int, channel: str = "CH1") -> np.ndarray:
    """The codes of ``channel`` that ``rig shot SCENE --seed SEED --set ... --export DIR``
    writes, read back from its files. The command runs in this process (its ``main``: the
    same parsing, shot and export, without a process's start-up of a second or more); the
    served shot it is compared with comes from the server's own process."""
    from rig.cli import main

    out = tmp_path / f"shot{seed}"
    sets = [a for o in overrides for a in ("--set", o)]
    assert main(["shot", SCENE, "--seed", str(seed), *sets, "--export", str(out)]) == 0
    (w,) = [w for f in sorted(out.iterdir()) for w in read_waveforms(f) if w.channel == channel]
    return w.codes


def test_it_says_where_it_listens_on_loopback(served):
    assert any(line.startswith("warm-up shot") for line in served.lines)
    assert served.resources[0].startswith("TCPIP::127.0.0.1::") and served.resources[0].endswith("::SOCKET")
    assert any("::hislip0," in r for r in served.resources)
    assert "TCPIP::127.0.0.1::INSTR" in served.resources  # VXI-11, found through port 111


def test_before_any_client_fires_the_scope_holds_the_warm_up_shot_at_the_first_seed(served, rm, tmp_path):
    """A script that only fetches (CURVe? with no acquisition of its own, as real scopes
    allow) gets the warm-up shot: the first shot, seed N, the rig shot of the settings the
    scope started with; the next shot takes seed N + 1."""
    scope = open_scope(rm, served.resource("SOCKET"))
    try:
        scope.write("*CLS;:HEADER OFF")
        assert scope.query("ACQUIRE:NUMACQ?").strip() == "1"
        assert int(scope.query("RIG:SEED?")) == FIRST_SEED + 1
        overrides = [o for o in scope.query("RIG:OVERRIDES?").strip().strip('"').split(",") if o]
        scope.write("DATA:SOURCE CH1;:DATA:ENCDG RIBINARY;:DATA:WIDTH 1;:DATA:START 1;:DATA:STOP 2500")
        codes = scope.query_binary_values("CURVE?", datatype="b", container=np.array, is_big_endian=True)
        assert scope.query("ALLEV?").strip().startswith("0,")  # nothing refused, no shot failed
    finally:
        scope.close()
    assert codes.size == 2500
    assert np.array_equal(codes, rig_shot_codes(tmp_path, overrides, FIRST_SEED))


# the last: VXI-11 by its core port, no portmapper asked
@pytest.mark.parametrize("kind", ["SOCKET", "hislip0", "127.0.0.1::INSTR", "127.0.0.1,"])
def test_a_shot_over_each_transport_is_the_rig_shot_of_its_settings_and_seed(served, rm, kind, tmp_path):
    codes, overrides, seed = shot_codes(rm, served.resource(kind))
    assert seed >= FIRST_SEED
    assert "scope.record_length=2500" in overrides  # a TDS2024C's record
    assert codes.size == 2500
    assert np.array_equal(codes, rig_shot_codes(tmp_path, overrides, seed))


def test_served_in_auto_an_untriggered_shot_is_the_rig_shot_of_its_items_and_seed(served, rm, tmp_path):
    """The served scope starts in AUTO, the models' default, which its shots carry as an item
    (scope.trigger.mode=auto): a rising edge at -0.4 V on gauges resting at 0 V never fires,
    and the shot's record is the bits of ``rig shot`` with the same items at the same seed."""
    scope = open_scope(rm, served.resource("SOCKET"))
    try:
        scope.write("*RST;:HEADER OFF")
        assert scope.query("TRIG:A:MODE?").strip() == "AUTO"
        scope.write("TRIG:A:EDGE:SLOPE RISE;:TRIG:A:LEVEL -0.4")
        assert float(scope.query("TRIG:A:LEVEL?")) == -0.4  # taken before another connection fires
        codes, overrides, seed = shot_codes(rm, served.resource("SOCKET"))
        assert scope.query("ALLEV?").strip().startswith("0,")  # no event: the record came
    finally:
        scope.write("*RST")
        scope.close()
    assert "scope.trigger.mode=auto" in overrides and "scope.trigger.level=-0.4 V" in overrides
    assert codes.size == 2500 and np.ptp(codes.astype(int)) > 25
    assert np.array_equal(codes, rig_shot_codes(tmp_path, overrides, seed))


def test_the_kth_shot_uses_seed_n_plus_k_minus_1_and_settings_apply_to_the_next(served, rm, tmp_path):
    resource = served.resource("SOCKET")
    scope = open_scope(rm, resource)
    try:
        before = int(scope.query("RIG:SEED?"))
        scope.write("CH1:SCALE 0.1;:RIG:STRIKER:VELOCITY 0.95 m/s")
        assert scope.query("*OPC?").strip() == "1"  # taken before this client goes
    finally:
        scope.close()
    codes, overrides, seed = shot_codes(rm, resource)
    assert seed == before
    assert "striker.velocity=0.95 m/s" in overrides
    assert any(o.startswith("scope.channels.CH1.volts_per_div=") for o in overrides)
    assert np.array_equal(codes, rig_shot_codes(tmp_path, overrides, seed))
    _, _, next_seed = shot_codes(rm, resource)
    assert next_seed == seed + 1


def test_a_bad_command_is_an_error_in_the_queue_and_the_server_answers_on(served, rm):
    scope = open_scope(rm, served.resource("SOCKET"))
    try:
        scope.write("*CLS")
        scope.write("NOSUCH:COMMAND 5")
        scope.write("RIG:MAGNET:FORCE -3 N")
        events = scope.query("ALLEV?")
        assert '113,"Undefined header' in events and '224,"Illegal parameter value' in events  # Tek's unsigned codes
        assert "TDS 2024C" in scope.query("*IDN?")
    finally:
        scope.close()


def test_sigterm_stops_it_cleanly_and_out_has_archived_the_warm_up_shot(tmp_path):
    from instruments.archive import Archive

    archive = tmp_path / "served.h5"
    s = Served(SCENE, "--port", "0", "--seed", "3", "--set", "striker.velocity=0.9 m/s", "--out", str(archive))
    code, rest = s.stop()
    assert code == 0, rest
    assert rest.strip().endswith("stopped")
    (number,) = Archive(archive).ids()  # the first shot, fired before the ports opened
    entry = Archive(archive).read(number)
    assert entry.seed == 3 and entry.record["CH1"].codes.size == 2500
    assert "striker.velocity=0.9 m/s" in entry.settings["overrides"]


@pytest.mark.parametrize("args, field", [
    (["nosuchscene"], "scene"),
    ([SCENE, "--fire", "every=-1"], "--fire"),
    ([SCENE, "--port", "70000"], "--port"),
    ([SCENE, "--personality", "tds9"], "--personality"),
    ([SCENE, "--set", "striker.velocity=fast"], "striker.velocity"),
    ([SCENE, "--idn", "junk"], "idn = 'junk'"),
    ([SCENE, "--host", "192.0.2.1"], "--host"),  # TEST-NET-1: no interface here has it
    ([SCENE, "--host", "no-such-host.invalid"], "--host"),
    ([SCENE, "--idle-timeout", "-1"], "--idle-timeout"),
    ([SCENE, "--stall-timeout", "0"], "--stall-timeout"),
    ([SCENE, "--max-clients", "4", "--per-address", "9"], "--per-address"),
])
def test_bad_input_is_one_line_and_exit_2(args, field, capsys):
    code, _, err = serve_in_process([*args, "--port", "0"] if "--port" not in args else args, capsys)
    assert code == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and field in lines[0], err
    assert lines[0].startswith("rig serve scope: error: ") and "Traceback" not in err


def test_a_port_in_use_is_one_line_naming_the_option(capsys):
    taken = socket.create_server(("127.0.0.1", 0))
    try:
        port = taken.getsockname()[1]
        code, _, err = serve_in_process([SCENE, "--port", str(port)], capsys)
    finally:
        taken.close()
    assert code == 2, err
    assert err.strip() == (f"rig serve scope: error: --port = {port}: a port free on 127.0.0.1 "
                           "(Address already in use), or 0 for any")


def serve_in_process(args: list, capsys, limit_s: float = 120.0) -> tuple:
    """(exit code, stdout, stderr) of ``rig serve scope ARGS`` refused in this process: what
    the command line's exit status and its one line say is what ``main`` returns (or the
    parser's SystemExit) and writes, without a process's start-up of a second or more. Run in
    a thread with a time limit, so that input the command wrongly accepts fails the test
    (a server is started: it cannot install its signal handlers off the main thread)
    instead of serving for ever."""
    import threading

    from rig.cli import main

    done: list = []

    def run():
        try:
            done.append(main(["serve", "scope", *args]))
        except SystemExit as exc:
            done.append(exc.code)
        except BaseException as exc:  # reported below, as the test's failure
            done.append(exc)

    worker = threading.Thread(target=run, daemon=True)
    worker.start()
    worker.join(limit_s)
    out, err = capsys.readouterr()
    assert done, f"rig serve scope {' '.join(args)}: still running after {limit_s} s; stdout: {out[-500:]}"
    if isinstance(done[0], BaseException):
        raise done[0]
    return done[0], out, err


def test_the_parsers_personalities_are_the_scopes():
    """The parser names them literally (it loads nothing of the instruments, for a quick
    --help): they must be the emulated scope's registry."""
    from instruments.virtual_scope.personalities import PERSONALITIES
    from rig.cli import build_parser

    serve = build_parser()._subparsers._group_actions[0].choices["serve"]
    scope = serve._subparsers._group_actions[0].choices["scope"]
    (action,) = [a for a in scope._actions if a.dest == "personality"]
    assert sorted(action.choices) == sorted(PERSONALITIES)


@pytest.mark.parametrize("host", ["192.0.2.1", "no-such-host.invalid"])
def test_a_bad_host_is_refused_before_the_warm_up_shot(host, capsys):
    code, out, err = serve_in_process([SCENE, "--host", host, "--port", "0"], capsys)
    assert code == 2 and "--host" in err
    assert "warm-up shot" not in out  # refused before seconds of compiling, not after


def test_the_parsers_wire_defaults_are_the_limits():
    """The parser names the defaults literally (it loads nothing of the instruments): they
    must be the transports' own."""
    from instruments.transports.wire import Limits
    from rig.cli import build_parser

    args = build_parser().parse_args(["serve", "scope", SCENE])
    limits = Limits()
    assert (args.idle_timeout, args.half_open_timeout, args.stall_timeout, args.max_clients, args.per_address) == (
        limits.idle_timeout_s, limits.half_open_timeout_s, limits.stall_timeout_s, limits.max_clients,
        limits.per_address)


def test_ipv6_loopback_is_served_and_its_resources_name_it_in_brackets():
    """In this process (``ScopeServer``, as ``rig serve scope --host ::1`` builds it: the
    resources are those its "listening" line prints)."""
    from rig.lab.serve import ScopeServer, ServeSettings

    if not socket.has_ipv6:
        pytest.skip("no IPv6 here")
    try:
        socket.create_server(("::1", 0), family=socket.AF_INET6).close()
    except OSError as e:
        pytest.skip(f"::1 cannot be listened on here ({e.strerror})")
    said: list = []
    server = ScopeServer(ServeSettings(scene=SCENE, host="::1", port=0, hislip=0, seed=2), say=said.append)
    try:
        assert not any("exposed" in line for line in said)  # ::1 is loopback
        port = server._socket.port
        assert server.resources[0] == f"TCPIP::[::1]::{port}::SOCKET"
        assert next(r for r in server.resources if "hislip0" in r).startswith("TCPIP::[::1]::hislip0,")
        with socket.create_connection(("::1", port), timeout=10) as c:
            c.sendall(b"*IDN?\n")
            assert c.recv(100).startswith(b"TEKTRONIX,TDS 2024C")
    finally:
        server.close()


def test_another_address_than_loopback_is_warned_of_and_named_as_remote_clients_open_it(tmp_path):
    from instruments.transports.addresses import machine_addresses
    from rig.lab.serve import ScopeServer, ServeSettings

    said = []
    server = ScopeServer(ServeSettings(scene=SCENE, host="0.0.0.0", port=0, hislip=0, seed=3, log=tmp_path / "l"),
                         say=said.append)
    try:
        warnings = [line for line in said if "exposed" in line]
        assert warnings == ["warning: the instrument is exposed unauthenticated on every address of this machine "
                            "(0.0.0.0): anyone who reaches it can command the scope and fire shots (--host 127.0.0.1 "
                            "keeps it on this machine)"]
        assert said.index(warnings[0]) < next(i for i, line in enumerate(said) if line.startswith("warm-up shot"))
        assert "0.0.0.0" not in " ".join(server.resources)
        addresses = machine_addresses("0.0.0.0")
        assert server.resources[0] == f"TCPIP::{addresses[0]}::{server._socket.port}::SOCKET"
        try:
            c = socket.create_connection((addresses[0], server._socket.port), timeout=5)
        except OSError:
            pytest.skip(f"{addresses[0]} cannot be reached from here")
        with c:
            c.sendall(b"*IDN?\n")
            assert c.recv(100).startswith(b"TEKTRONIX,TDS 2024C")
    finally:
        server.close()
    assert "WARNING warning: the instrument is exposed unauthenticated" in (tmp_path / "l").read_text()
