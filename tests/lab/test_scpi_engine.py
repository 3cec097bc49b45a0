"""The SCPI engine on a small command tree: path inheritance, reply forms, the events each
fault queues, and the IEEE 488.2 status registers."""
import pytest

from instruments.scpi.engine import Engine, Fields, Word
from instruments.scpi.status import CME, DDE, ESB, EXE, MSS, PON, QUEUE_SIZE, QYE, ScpiError, StatusModel
from instruments.scpi.tree import CommandTree


@pytest.fixture
def engine():
    state = {"enc": "RIBinary", "width": 1, "scale": {}}
    tree = CommandTree()

    def set_width(c):
        c.only(1)
        w = c.number()
        if w not in (1, 2):
            raise ScpiError(-222, f"{c.header} {w:g}")
        state["width"] = int(w)

    tree.add("DATa:ENCdg", write=lambda c: state.update(enc=c.word(("ASCIi", "RIBinary"))),
             read=lambda c: Word(state["enc"]))
    tree.add("DATa:WIDth", write=set_width, read=lambda c: str(state["width"]))
    tree.add("CH<n>:SCAle", write=lambda c: state["scale"].update({c.suffix: c.number("V")}),
             read=lambda c: f"{state['scale'].get(c.suffix, 0.1):g}")
    tree.add("WFMPre", read=lambda c: Fields((("BYT_Nr", "1"), ("ENCdg", Word("BINary")), ("WFId", '"a;b"'))))
    tree.add("*IDN", read=lambda c: "TEK,X,1,2", bare=True)
    tree.add("*CLS", write=lambda c: e.status.clear())
    e = Engine(tree)
    e.form.header = False
    e.state = state
    return e


def run(engine, text):
    return engine.execute(text.encode())


def codes(engine):
    return [ev.code for ev in engine.status.events]


def test_path_inheritance_and_common_commands_keep_the_path(engine):
    assert run(engine, "DATA:ENCDG ASCII;WIDTH 2;*IDN?;WIDTH?;ENC?") == b"TEK,X,1,2;2;ASCII\n"
    assert engine.state == {"enc": "ASCIi", "width": 2, "scale": {}}
    assert run(engine, ":CH2:SCA 20mV;:CH3:SCALE 0.5;SCALE?;:CH2:SCA?") == b"0.5;0.02\n"
    assert codes(engine) == []


def test_a_new_message_starts_at_the_root(engine):
    run(engine, "DATA:WIDTH 2")
    assert run(engine, "WIDTH?") == b""
    assert codes(engine) == [-113]


def test_a_relative_header_that_names_nothing_below_the_path_is_read_from_the_root(engine):
    assert run(engine, "CH1:SCALE 0.2;CH2:SCALE 0.3;CH1:SCALE?") == b"0.2\n"


def test_header_and_verbose_reply_forms(engine):
    engine.form.header = True
    assert run(engine, "DATA:ENCDG?;:DAT:WID?;*IDN?") == b":DATA:ENCDG RIBINARY;:DATA:WIDTH 1;TEK,X,1,2\n"
    assert run(engine, "WFMPRE?") == b':WFMPRE:BYT_NR 1;ENCDG BINARY;WFID "a;b"\n'
    engine.form.verbose = False
    assert run(engine, "DATA:ENCDG?;:CH3:SCA?") == b":DAT:ENC RIB;:CH3:SCA 0.1\n"
    assert run(engine, "WFMPRE?") == b':WFMP:BYT_N 1;ENC BIN;WFI "a;b"\n'
    engine.form.header = False
    assert run(engine, "DATA:ENCDG?;WFMPRE?") == b'RIB;1;BIN;"a;b"\n'


@pytest.mark.parametrize("message, code, bit", [
    ("DATA:FOO 1", -113, CME), ("DATA:ENCDG BOGUS", -224, EXE), ("DATA:WIDTH 3", -222, EXE),
    ("DATA:WIDTH", -109, CME), ("DATA:WIDTH 1,2", -108, CME), ("DATA:WIDTH ON", -104, CME),
    ("CH1:SCALE 5 s", -131, CME), ("DATA:WIDTH 1 @", -141, CME), ("*IDN", -113, CME), ("DATA:ENCDG? 'x", -150, CME)])
def test_each_fault_queues_its_event_and_sets_its_esr_bit(engine, message, code, bit):
    engine.status.esr = 0
    assert run(engine, message) == b""
    assert codes(engine) == [code]
    assert engine.status.esr == bit


def test_a_failing_query_answers_nothing_and_the_others_still_answer(engine):
    assert run(engine, "DATA:WIDTH?;NOPE?;ENCDG?") == b"1;RIBINARY\n"
    assert codes(engine) == [-113]


def test_event_text_and_the_queue_overflow():
    status = StatusModel()
    for k in range(QUEUE_SIZE + 5):
        status.post(-222, f"value {k}")
    events = [status.next_event() for _ in range(QUEUE_SIZE)]
    assert [e.code for e in events[:-1]] == [-222] * (QUEUE_SIZE - 1)
    assert events[-1].code == -350 and events[-1].text() == '350,"Queue overflow"' \
        and events[-1].text(scpi=True) == '-350,"Queue overflow"'
    assert events[0].text() == '222,"Data out of range; value 0"'
    assert status.next_event().text() == '0,"No events to report - queue empty"'


def test_status_byte_esb_and_mss():
    status = StatusModel()
    assert status.read_esr() == PON and status.read_esr() == 0
    status.post(-410)
    assert status.esr == QYE and status.status_byte(False) == 0
    status.ese = QYE
    assert status.status_byte(False) == ESB
    status.sre = ESB
    assert status.status_byte(True) == ESB | MSS | 16
    status.post(-363)
    assert status.esr == QYE | DDE
    status.clear()
    assert status.esr == 0 and status.status_byte(False) == 0
