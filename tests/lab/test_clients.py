"""Lab client libraries, unchanged, against the scope ``rig serve scope`` serves (built in
this process as the command builds it, ``ScopeServer``: what is tested is the wire between
a client and the server, not the server's process): tm_devices (raw socket, the
server claiming an MSO44), qcodes' Tektronix drivers ``TPS2012`` (a TDS2024C over VXI-11:
its ``WAVFrm?`` parser needs the reply's closing newline, which a raw socket's read
strips) and ``DPO7200xx`` (the mso4 personality, raw socket), and three of Tektronix's own
example scripts (Programmatic-Control-Examples, run from a checkout named by
RIG_TEK_EXAMPLES, with only their resource string changed). Each waveform a client reads
is compared with the record of the same shot as the rig computes it in this process
(``SceneShots`` at the overrides and seed the server reports, the bits of ``rig shot``):
the same codes, and volts within a thousandth of one code's step."""
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

pyvisa = pytest.importorskip("pyvisa")

from lab.served import Tap, open_scope, resource
from rig.lab.serve import ScopeServer, ServeSettings
from rig.lab.shots import SceneShots

SCENE = "ptfe52_magnetic"
MSO44 = "TEKTRONIX,MSO44,C012345,CF:91.1CT FV:2.0.3.950"  # a model tm_devices knows
OLD_NAMES = Path(__file__).parent / "old_names"  # sitecustomize: `import visa`, np.float
GET_EXAMPLES = ("RIG_TEK_EXAMPLES unset: git clone https://github.com/tektronix/Programmatic-Control-Examples "
                "and set RIG_TEK_EXAMPLES to the clone (the folder holding Examples/Oscilloscopes)")


def served(**settings):
    """``rig serve scope SCENE --port 0 --hislip 0`` with ``settings`` (ServeSettings' fields)."""
    server = ScopeServer(ServeSettings(scene=SCENE, port=0, hislip=0, **settings), say=lambda line: None)
    yield server
    server.close()


@pytest.fixture(scope="module")
def tds(port111):
    """A TDS2024C (2,500 points, 8 bit) on a raw socket, HiSLIP and VXI-11."""
    yield from served(vxi11=True, personality="tds2000", seed=21)


@pytest.fixture(scope="module")
def mso():
    """A 4 Series MSO (10,000 points) that says it is an MSO44, on a raw socket and HiSLIP."""
    yield from served(personality="mso4", idn=MSO44, seed=31)


@pytest.fixture(scope="module")
def rig_shots():
    return SceneShots(SCENE)


def held_record(rm, server: ScopeServer, rig_shots: SceneShots, channel: str = "CH1"):
    """(the waveform of ``channel`` in the record the served scope holds, as the rig
    computes it here: the shot at the seed before ``RIG:SEED?`` with ``RIG:OVERRIDES?``;
    the server's event queue, read out)."""
    scope = open_scope(rm, resource(server.resources, "SOCKET"))
    try:
        scope.write("HEADER OFF")
        seed = int(scope.query("RIG:SEED?")) - 1
        items = [o for o in scope.query("RIG:OVERRIDES?").strip().strip('"').split(",") if o]
        events = scope.query("ALLEV?").strip()
    finally:
        scope.close()
    record = rig_shots(dict(item.split("=", 1) for item in items), seed)
    assert record.triggered, record.reason
    return record[channel], events


def assert_same_volts(volts, waveform) -> None:
    """The client's volts are the record's, to a thousandth of one code's step."""
    assert np.shape(volts) == waveform.codes.shape
    np.testing.assert_allclose(volts, waveform.volts(), rtol=0, atol=1e-3 * waveform.preamble.y_multiplier)
    # a pulse over a division high, not a flat line that matches anything
    assert np.ptp(waveform.codes.astype(np.int64)) > 25


@pytest.mark.filterwarnings("ignore:A VISA IO error occurred when attempting to read the status byte")
def test_tm_devices_knows_the_mso44_and_its_curve_query_is_the_record(mso, rm, rig_shots):
    """tm_devices identifies the model from ``*IDN?`` (asked more than once as it connects)
    and reads CH1 with its own ``curve_query`` (``:DATA:ENC ASCII`` checked by reading it
    back, then ``:CURVE?``). pyvisa-py's socket has no status byte: tm_devices warns and
    goes on, as with a real scope on a socket."""
    from tm_devices import DeviceManager, configure_logging
    from tm_devices.drivers import MSO4
    from tm_devices.helpers import LoggingLevels

    # no log files (it writes ./logs by default), no console lines, the test's excepthook kept
    configure_logging(log_console_level=LoggingLevels.NONE, log_file_level=LoggingLevels.NONE,
                      log_uncaught_exceptions=False)

    tap = Tap(mso._socket.port)
    try:
        with DeviceManager(verbose=False) as dm:
            dm.setup_cleanup_enabled = False
            dm.teardown_cleanup_enabled = False
            dm.visa_library = "@py"
            scope = dm.add_scope("127.0.0.1", connection_type="SOCKET", port=tap.port)
            assert isinstance(scope, MSO4) and scope.model == "MSO44"
            values = scope.curve_query(1)
            width = int(scope.query("DATA:WIDTH?"))
    finally:
        tap.close()
    sent = tap.messages()
    assert sent.count("*IDN?") >= 2 and ":DATA:ENC ASCII" in sent and ":CURVE?" in sent, sent
    waveform, events = held_record(rm, mso, rig_shots)
    assert events.startswith("0,"), events  # nothing tm_devices sent was refused
    assert np.array_equal(np.asarray(values), waveform.codes.astype(np.int64) * 256 ** (width - 1))


# --- Tektronix's example scripts ---------------------------------------------------------
EXAMPLES = {
    # script (under Examples/Oscilloscopes), the variable naming its resource, server, transport;
    # the fetch example first: it fires no shot and, run before any client fires, gets the
    # record the scope holds from its start (the warm-up shot)
    "fetch": ("PerformanceScopes/src/FetchWaveformDataExample/MSO DPO 5K 7K 70K Fetch Waveform Data.py",
              "visaResourceAddr", "mso", "hislip0"),
    "tbs": ("BenchScopes/src/SimplePlotExample/tbs_simple_plot.py", "visa_address", "tds", "hislip0"),
    "mdo": ("MidrangeScopes/src/SimplePlotExample/mdo_simple_plot.py", "visa_address", "mso", "hislip0"),
}
RUN_KEEPING_ARRAYS = ("import runpy, sys, numpy; g = runpy.run_path(sys.argv[1], run_name='__main__'); "
                      "numpy.savez(sys.argv[2], **{k: v for k, v in g.items() if type(v) is numpy.ndarray})")
"""Runs a script as ``python script`` does and keeps the numpy arrays it ends with."""


@pytest.fixture(scope="module")
def tek_examples():
    folder = os.environ.get("RIG_TEK_EXAMPLES")
    if not folder:
        pytest.skip(GET_EXAMPLES)
    root = Path(folder) / "Examples" / "Oscilloscopes"
    if not root.is_dir():
        pytest.fail(f"RIG_TEK_EXAMPLES = {folder}: no Examples/Oscilloscopes in it; {GET_EXAMPLES}")
    return root


def with_resource(script: Path, variable: str, resource: str) -> str:
    """The script's text with only its resource string changed."""
    text, n = re.subn(rf"^{variable} = '[^']*'$", f"{variable} = {resource!r}", script.read_text(), flags=re.MULTILINE)
    assert n == 1, f"{script.name}: no single line `{variable} = '...'` to put the resource in"
    return text


@pytest.mark.parametrize("name", list(EXAMPLES))
def test_a_tektronix_example_runs_unchanged_and_ends_with_the_record(name, tek_examples, request, rm, rig_shots,
                                                                     tmp_path):
    path, variable, server, transport = EXAMPLES[name]
    served = request.getfixturevalue(server)
    script = tmp_path / "example.py"
    script.write_text(with_resource(tek_examples / path, variable, resource(served.resources, transport)))
    paths = [str(OLD_NAMES), *filter(None, os.environ.get("PYTHONPATH", "").split(os.pathsep))]
    env = os.environ | {"PYTHONPATH": os.pathsep.join(paths),
                        "PYVISA_LIBRARY": "@py", "MPLBACKEND": "Agg"}
    run = subprocess.run([sys.executable, "-c", RUN_KEEPING_ARRAYS, str(script), str(tmp_path / "end.npz")],
                         input="\n", check=False, capture_output=True, text=True, cwd=tmp_path, env=env, timeout=300)
    assert run.returncode == 0, run.stdout + run.stderr
    waveform, events = held_record(rm, served, rig_shots)
    assert events.startswith("0,"), events
    end = np.load(tmp_path / "end.npz")
    if name == "fetch":  # it never fires: the record it fetches is the one the scope holds
        volts = np.load(tmp_path / "yvalues_numpy_array.dat", allow_pickle=True)
        assert np.array_equal(end["rawData"], waveform.codes)
    else:
        assert "event status register: 0b00000000" in run.stdout, run.stdout
        assert 'all event messages: 0,"No events to report' in run.stdout, run.stdout
        volts = end["scaled_wave"]
        assert end["scaled_time"].size == volts.size
    assert_same_volts(volts, waveform)


def test_qcodes_dpo7200xx_trace_is_the_record_in_volts(mso, rm, rig_shots):
    """qcodes' DPO7200xx (the 5K/7K/70K driver) on the mso4: a single sequence fired with
    the driver's own acquisition parameters, then its trace: ``CURVE?`` in the binary
    format its WFMOutpre parameters read, ``(code - YOFF) * YMULT + YZERO``."""
    from qcodes.instrument_drivers.tektronix.DPO7200xx import TektronixDPO7000xx

    dpo = TektronixDPO7000xx("rig_dpo", resource(mso.resources, "SOCKET"), visalib="@py")
    try:
        assert dpo.get_idn()["model"] == "MSO44"
        dpo.acquisition.stop_after("SEQUENCE")
        dpo.acquisition.state("RUN")
        assert dpo.ask("*OPC?") == "1"
        volts = dpo.channel1.waveform.trace()
        assert dpo.channel1.waveform.length() == volts.size
        dt = dpo.channel1.waveform.x_increment()
    finally:
        dpo.close()
    waveform, events = held_record(rm, mso, rig_shots)
    assert events.startswith("0,"), events
    assert_same_volts(volts, waveform)
    assert dt == pytest.approx(waveform.preamble.x_increment, rel=1e-4)


def test_qcodes_tps2012_curvedata_is_the_record_in_volts(tds, rm, rig_shots):
    """qcodes' TPS2012 on the TDS2024C over VXI-11: 16-bit RPBinary, ``WAVFrm?`` parsed as
    16 preamble fields and a block whose closing newline it cuts off. Its volts are
    ``YMULT (code - YOFF)``: the driver leaves YZERO (the channel's offset) out."""
    from qcodes.instrument_drivers.tektronix.TPS2012 import TektronixTPS2012

    tps = TektronixTPS2012("rig_tps", resource(tds.resources, "127.0.0.1::INSTR"), visalib="@py")
    try:
        assert tps.get_idn()["model"] == "TDS 2024C"
        tps.ch1.curvedata.prepare_curvedata()
        volts = tps.ch1.curvedata.get()
    finally:
        tps.close()
    waveform, events = held_record(rm, tds, rig_shots)
    assert events.startswith("0,"), events
    assert waveform.codes.size == 2500
    assert_same_volts(np.asarray(volts) + waveform.preamble.y_zero, waveform)


def test_a_curvestream_program_reads_the_next_shots_of_the_rig_block_by_block(mso, rm, rig_shots):
    """A lab program's stream, its address alone changed: CURVESTREAM? written, then a
    binary block read per acquisition; each block is the rig's shot at the next seed, code
    for code, and a command ends the stream (the socket drained, as VISA's clear does)."""
    scope = open_scope(rm, resource(mso.resources, "SOCKET"))
    try:
        scope.write("*CLS;:HEADER OFF;:DATA:SOURCE CH1;:DATA:ENCDG SRIBINARY;:DATA:WIDTH 2;:DATA:START 1;"
                    ":DATA:STOP 100000")
        seed = int(scope.query("RIG:SEED?"))
        items = [o for o in scope.query("RIG:OVERRIDES?").strip().strip('"').split(",") if o]
        scope.write("CURVESTREAM?")
        blocks = [scope.read_binary_values(datatype="h", is_big_endian=False, container=np.array) for _ in range(3)]
        scope.write("*CLS")
        scope.clear()
        assert int(scope.query("RIG:SEED?")) >= seed + 3 and scope.query("*ESR?").strip() == "0"
    finally:
        scope.close()
    for k, codes in enumerate(blocks):
        expected = rig_shots(dict(item.split("=", 1) for item in items), seed + k)["CH1"].codes
        assert np.array_equal(codes, expected.astype(np.int16) * 256), k  # DATa:WIDth 2: the code in the high byte
