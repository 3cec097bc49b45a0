"""CURVe? and the preamble: in every encoding and width, the bytes decode back to the
record's codes and the preamble turns them into the record's volts and times, read both by
a plain decoder here and by the rig's ISF reader from the scope's own header-on replies."""
import numpy as np
import pytest

from instruments.formats.isf import read_isf
from instruments.scpi.blocks import block_payload
from lab.lab_scope import ask, fire

ENCODINGS = ("ASCIi", "RIBinary", "RPBinary", "SRIbinary", "SRPbinary")


def preamble(session, name):
    """{field: text} of a header-off preamble reply, by the personality's field names."""
    from instruments.virtual_scope.personalities import WFMOUTPRE_4SERIES, WFMOUTPRE_22, WFMPRE_16
    fields = WFMPRE_16 if name == "WFMPre" else WFMOUTPRE_4SERIES if "MSO4" in ask(session, "*IDN?") else WFMOUTPRE_22
    values = ask(session, f"{name}?").split(";")
    assert len(values) == len(fields)
    return {f.upper(): v for f, v in zip(fields, values)}


def decode(reply: bytes, pre: dict) -> np.ndarray:
    """The codes of a CURVe? reply, read as its preamble says."""
    if pre["ENCDG"] in ("ASCII", "ASC"):
        return np.array([int(x) for x in reply.decode().strip().split(",")])
    order = "<" if pre["BYT_OR"] == "LSB" else ">"
    kind = "u" if pre["BN_FMT"] == "RP" else "i"
    return np.frombuffer(block_payload(reply.rstrip(b"\n")), f"{order}{kind}{pre['BYT_NR']}").astype(np.int64)


@pytest.mark.parametrize("personality, name", [("tds2000", "WFMPre"), ("mdo3000", "WFMOutpre"),
                                               ("mso4", "WFMOutpre")])
@pytest.mark.parametrize("encoding", ENCODINGS)
@pytest.mark.parametrize("width", (1, 2))
def test_bytes_and_preamble_give_the_records_volts(make_scope, personality, name, encoding, width, tmp_path):
    scope, s, _ = make_scope(personality, seed=3)
    fire(s)
    record = scope.acq.last.record["CH1"]
    s.handle(f"DATA:SOURCE CH1;ENCDG {encoding};WIDTH {width};START 101;STOP 1600".encode())
    pre = preamble(s, name)
    assert (int(pre["BYT_NR"]), int(pre["BIT_NR"]), int(pre["NR_PT"])) == (width, 8 * width, 1500)
    codes = decode(s.handle(b"CURVE?"), pre)
    assert codes.size == 1500
    factor = 256 if width == 2 else 1
    unsigned = encoding in ("RPBinary", "SRPbinary")
    expected = record.codes[100:1600].astype(np.int64) * factor + (128 * factor if unsigned else 0)
    assert np.array_equal(codes, expected)
    volts = float(pre["YZERO"]) + float(pre["YMULT"]) * (codes - float(pre["YOFF"]))
    assert np.allclose(volts, record.volts()[100:1600], rtol=0, atol=1e-12)
    t = float(pre["XZERO"]) + float(pre["XINCR"]) * np.arange(codes.size)
    assert np.allclose(t, record.time()[100:1600], rtol=0, atol=1e-15)

    s.handle(b"HEADER ON")  # the scope's own replies, one after the other, are an ISF file
    isf = tmp_path / "ch1.isf"
    isf.write_bytes(s.handle(f"{name}?".encode()).rstrip(b"\n") + b";" + s.handle(b"CURVE?"))
    (w,) = read_isf(isf)
    assert w.channel == "CH1" and w.codes.size == 1500
    assert np.allclose(w.volts(), record.volts()[100:1600], rtol=0, atol=1e-12)
    assert np.allclose(w.time(), record.time()[100:1600], rtol=0, atol=1e-15)


@pytest.mark.parametrize("personality", ["tds2000", "mdo3000", "mso4"])
@pytest.mark.parametrize("encoding, width", [("RIBinary", 1), ("SRPbinary", 1), ("RPBinary", 2), ("ASCIi", 2)])
def test_yoff_and_yzero_are_each_models_own(make_scope, personality, encoding, width):
    """WFMOutpre:YOFf (MDO3000 and 4 Series manuals): "For this instrument family, the value
    returned is always 0.0 as the offset is combined with the :YZEro value"; YZEro "returns
    the combined vertical position and offset". The TDS2000 keeps its own: YOFf the position
    in digitizing levels (-1 div: -25 codes, x 256 at width 2, + 2^(8 width - 1) unsigned),
    YZEro the offset. Either way YZERO + YMULT (code - YOFF) is the record's volts, and the
    whole preamble says the same as its fields."""
    scope, s, _ = make_scope(personality, seed=2)
    s.handle(b"CH1:POSITION -1;OFFSET 0.02")  # -1 div at 50 mV/div, 20 mV offset
    fire(s)
    s.handle(f"DATA:SOURCE CH1;ENCDG {encoding};WIDTH {width};START 1;STOP 100000".encode())
    name = "WFMPre" if personality == "tds2000" else "WFMOutpre"
    pre = preamble(s, name)
    assert (pre["YOFF"], pre["YZERO"]) == tuple(ask(s, f"{name}:YOFF?;YZERO?").split(";"))
    factor = 256 if width == 2 else 1
    unsigned = 128 * factor if encoding in ("RPBinary", "SRPbinary") else 0
    if personality == "tds2000":
        assert float(pre["YOFF"]) == -25 * factor + unsigned and float(pre["YZERO"]) == pytest.approx(0.02, rel=1e-12)
    else:
        assert pre["YOFF"] == "0.0E+0"
        code_zero = 0.02 + 0.05 - unsigned * 0.002 / factor  # the volts of the code 0 as sent
        assert float(pre["YZERO"]) == pytest.approx(code_zero, rel=1e-12)
    codes = decode(s.handle(b"CURVE?"), pre)
    volts = float(pre["YZERO"]) + float(pre["YMULT"]) * (codes - float(pre["YOFF"]))
    assert np.allclose(volts, scope.acq.last.record["CH1"].volts(), rtol=0, atol=1e-12)


def test_wavfrm_is_the_preamble_then_the_curve(make_scope):
    _scope, s, _ = make_scope("tds2000", seed=1)
    fire(s)
    s.handle(b"DATA:ENCDG RPBINARY;WIDTH 2")
    reply = s.handle(b"WAVFRM?")
    fields = reply.split(b";", 16)
    assert b";".join(fields[:16]).decode() == ask(s, "WFMPRE?")
    assert fields[16] == s.handle(b"CURVE?")
    s.handle(b"HEADER ON")
    assert s.handle(b"WAVFRM?") == s.handle(b"WFMPRE?;CURVE?")
    assert s.handle(b"WAVFRM?").startswith(b":WFMPRE:BYT_NR 2;")


def test_stop_past_the_record_is_clipped_and_start_past_it_sends_the_last_point(make_scope):
    scope, s, _ = make_scope("tds2000", seed=1)
    fire(s)
    s.handle(b"DATA:ENCDG ASCII;START 2400;STOP 100000")
    assert ask(s, "WFMPRE:NR_PT?") == "101" and len(ask(s, "CURVE?").split(",")) == 101
    s.handle(b"DATA:START 9000")
    assert ask(s, "WFMPRE:NR_PT?") == "1" and ask(s, "CURVE?") == str(scope.acq.last.record["CH1"].codes[-1])


def test_preamble_before_any_shot_follows_the_settings(make_scope):
    _scope, s, _ = make_scope("mdo3000")
    assert ask(s, "*ESR?") == "128"  # power on
    s.handle(b"CH1:SCALE 0.2;:HORIZONTAL:SCALE 400E-6")
    pre = preamble(s, "WFMOutpre")
    assert pre["YMULT"] == "8.0000E-3" and pre["XINCR"] == "400.0000E-9"
    assert pre["WFID"] == '"Ch1, DC coupling, 200.0mV/div, 400.0us/div, 10000 points, Sample mode"'
    assert ask(s, "CURVE?;*ESR?") == "#10;16" and ask(s, "ALLEV?").startswith('200,"Execution error; CH1 has no record')


@pytest.mark.parametrize("fields, encoding", [
    ("ENCDG BINARY;BN_FMT RP;BYT_OR LSB", "SRPBINARY"), ("BN_FMT RP;BYT_OR MSB", "RPBINARY"),
    ("BYT_OR LSB", "SRIBINARY"), ("ENCDG ASCII;BN_FMT RP", "ASCII"), ("ENCDG ASCII;BN_FMT RP;ENCDG BIN", "RPBINARY")])
def test_the_preambles_format_fields_set_the_data_encoding(make_scope, fields, encoding):
    _scope, s, _ = make_scope("mso4")
    s.handle(f"WFMOUTPRE:{fields}".encode())
    assert ask(s, "DATA:ENCDG?") == encoding
    bn_fmt, byt_or = ask(s, "WFMO:BN_FMT?;BYT_OR?").split(";")
    assert bn_fmt == ("RP" if "BN_FMT RP" in fields else "RI")
    assert byt_or == ("LSB" if "LSB" in fields else "MSB")
    s.handle(b"WFMO:BN_FMT FP")  # the 4 Series manual: floats, BYT_NR 4, the byte order kept
    assert ask(s, "DATA:ENCDG?;:WFMO:BYT_NR?;BIT_NR?;EVENT?") == (
        f"{'SFPBINARY' if byt_or == 'LSB' else 'FPBINARY'};4;32;0" if encoding != "ASCII" else "ASCII;4;32;0")


@pytest.mark.parametrize("personality, command, refused", [
    ("mdo3000", "DATA:ENC FASTEST", None), ("mdo3000", "DATA:ENC FPBINARY", None), ("mso4", "DATA:ENC SFP", None),
    ("mso4", "WFMO:BYT_NR 4", None), ("mso4", "WFMO:BIT_NR 32", None), ("mso4", "DATA:ENC FAS", "224"),
    ("tds2000", "DATA:ENC FPB", "224"), ("tds2000", "WFMPRE:BN_FMT FP", "224"), ("tds2000", "WFMPRE:BYT_NR 4", "222")])
def test_the_encodings_of_each_models_manual(make_scope, personality, command, refused):
    """DATa:ENCdg takes the words of the model's manual: the MDO3000's FAStest (signed,
    MSB first) and FPBinary, the 4 Series' FPBinary and SFPbinary (4-byte floats whose
    preamble turns them into the record's volts); the TDS2000's integers only."""
    scope, s, _ = make_scope(personality, seed=3)
    s.handle(command.encode())
    assert ask(s, "EVENT?") == (refused or "0")
    if refused:
        return
    fire(s)
    s.handle(b"DATA:SOURCE CH1;START 1;STOP 500")
    pre = preamble(s, "WFMOutpre")
    floats = pre["BN_FMT"] == "FP"
    assert floats == ("FAS" not in command) and pre["BYT_NR"] == ("4" if floats else "1")
    payload = block_payload(s.handle(b"CURVE?").rstrip(b"\n"))
    kind = "f4" if floats else "i1"
    values = np.frombuffer(payload, ("<" if pre["BYT_OR"] == "LSB" else ">") + kind)
    volts = float(pre["YZERO"]) + float(pre["YMULT"]) * (values - float(pre["YOFF"]))
    assert values.size == 500
    assert np.allclose(volts, scope.acq.last.record["CH1"].volts()[:500], rtol=0, atol=1e-12)


def test_data_query_and_init(make_scope):
    _scope, s, _ = make_scope("tds2000")
    s.handle(b"DATA:ENC ASCII;SOURCE CH2;START 5;STOP 50;WIDTH 2")
    assert ask(s, "DATA?") == "REFA;ASCII;CH2;5;50;2"
    s.handle(b"DATA INIT")
    assert ask(s, "DATA?") == "REFA;RIBINARY;CH1;1;2500;1"


def test_a_list_of_sources_is_taken_where_the_manual_has_one(make_scope):
    """DATa:SOUrce CH1,CH2 (4 Series, MDO3000 manuals): taken and read back; the preamble is
    the first source's; CURVe? answers one source at a time (221 and an empty block at once
    for the list); the TDS2000 takes one source (108 for the rest)."""
    _scope, s, _ = make_scope("mso4")
    fire(s)
    s.handle(b"DATA:SOURCE CH1,CH2")
    assert ask(s, "DATA:SOURCE?;:WFMO:WFID?;:EVENT?").startswith('CH1,CH2;"Ch1, ')
    assert s.handle(b"CURVE?") == b"#10\n" and ask(s, "EVENT?") == "221"
    s.handle(b"DATA:SOURCE CH2")
    assert ask(s, "DATA:SOURCE?") == "CH2" and len(block_payload(s.handle(b"CURVE?").rstrip(b"\n"))) > 0
    _scope, tds, _ = make_scope("tds2000")
    tds.handle(b"DATA:SOURCE CH2,CH1")
    assert ask(tds, "DATA:SOURCE?;:EVENT?") == "CH2;108"


@pytest.mark.parametrize("personality", ["mdo3000", "tds2000"])
def test_a_model_whose_manual_takes_one_source_refuses_a_list(make_scope, personality):
    """The MDO3000's and TDS2000's manuals: ``DATa:SOUrce {CH<x>|MATH|REF<x>|...}``, one
    source: a list is 108 "Parameter not allowed", the first source taken; CURVe? sends it."""
    _scope, s, _ = make_scope(personality)
    fire(s)
    s.handle(b"DATA:SOURCE CH2,CH1")
    assert ask(s, "DATA:SOURCE?;:EVENT?;:EVENT?") == "CH2;108;0"
    assert len(block_payload(s.handle(b"CURVE?").rstrip(b"\n"))) > 0 and ask(s, "EVENT?") == "0"
