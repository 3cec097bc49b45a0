"""Scope-file readers: real Tektronix files, both CSV layouts, and malformed files."""
import numpy as np
import pytest

from instruments.errors import InstrumentError
from instruments.formats import read_csv, read_isf
from instruments.formats.isf import isf_bytes
from instruments.records import Preamble, Waveform


def test_real_16bit_dpo_file(realdata):
    (w,) = read_isf(realdata / "tek_16bit_dpo.isf")
    v = w.volts()
    assert w.preamble.points == 10000 and w.codes.dtype == np.int16
    assert (v.min(), v.max()) == (pytest.approx(-7.3), pytest.approx(17.1))
    assert w.preamble.x_increment == 400e-12 and w.preamble.x_zero == pytest.approx(-1.6012e-6)


def test_real_8bit_file_with_two_records_reads_both(realdata):
    first, second = read_isf(realdata / "tek_8bit_two_records.isf")
    v = first.volts()
    assert first.preamble.points == 1_250_000 and first.preamble.x_increment == 8e-9
    assert (v.min(), v.max(), v[0]) == (pytest.approx(0.3), pytest.approx(4.9), pytest.approx(0.9))
    assert second.channel == "CH1#2" and second.preamble.point_format == "ENV"


def _isf(tmp_path, data: bytes):
    p = tmp_path / "x.isf"
    p.write_bytes(data)
    return p


def _wave(n=100):
    pre = Preamble(points=n, x_increment=1e-6, x_zero=-1e-5, trigger_index=10, y_multiplier=0.01,
                   y_offset=0.0, y_zero=0.0)
    return Waveform("CH1", pre, codes=(np.arange(n) % 50).astype(np.int8))


def test_our_isf_round_trips(tmp_path):
    w = _wave()
    (back,) = read_isf(_isf(tmp_path, isf_bytes(w)))
    assert np.array_equal(back.codes, w.codes) and back.preamble.trigger_index == 10


@pytest.mark.parametrize("mangle,message", [
    (lambda b: b[:-30], "truncated curve block"),
    (lambda b: b.replace(b"NR_PT 100", b"NR_PT 120"), "header says 120 points"),
    (lambda b: b.replace(b"YMULT", b"YMULX"), r"header field\(s\) missing: YMULT"),
    (lambda b: b.replace(b"XINCR 1.0", b"XINCR x.0"), "XINCR"),
    (lambda b: b"hello world", "no :CURVE block"),
])
def test_malformed_isf_names_the_file_and_the_problem(tmp_path, mangle, message):
    p = _isf(tmp_path, mangle(isf_bytes(_wave())))
    with pytest.raises(InstrumentError, match=message) as err:
        read_isf(p)
    assert str(p) in str(err.value)


TDS = """Record Length,5,,-0.000002,0.01,
Sample Interval,1e-06,,-0.000001,0.02,
Trigger Point,2,,0.000000,0.50,
,,,0.000001,0.30,
Source,CH2,,0.000002,0.10,
"""
DPO = """Model,MSO54
Sample Interval,1e-06
Record Length,5
Zero Index,2
Vertical Units,V,V

TIME,CH1,CH2
-2e-06,0.01,0.2
-1e-06,0.02,0.3
0,0.5,0.4
1e-06,0.3,0.5
2e-06,0.1,0.6
"""


def test_tds_csv_layout(tmp_path):
    p = tmp_path / "tds.csv"
    p.write_text(TDS)
    (w,) = read_csv(p)
    assert w.channel == "CH2" and w.preamble.trigger_index == 2 and w.preamble.x_increment == 1e-6
    assert np.allclose(w.volts(), [0.01, 0.02, 0.5, 0.3, 0.1])
    assert np.allclose(w.time(), [-2e-6, -1e-6, 0, 1e-6, 2e-6])


def test_dpo_csv_layout(tmp_path):
    p = tmp_path / "dpo.csv"
    p.write_text(DPO)
    a, b = read_csv(p)
    assert (a.channel, b.channel) == ("CH1", "CH2")
    assert np.allclose(b.volts(), [0.2, 0.3, 0.4, 0.5, 0.6]) and a.preamble.trigger_index == 2


@pytest.mark.parametrize("text,message", [
    (DPO.replace("0.3,0.5", "0.3,abc"), "non-numeric value 'abc'"),
    (TDS.replace("Record Length,5", "Record Length,7"), "Record Length says 7 points"),
    (TDS.replace("Sample Interval,1e-06", "Sample Rate,1e-06"), "Sample Interval"),
    (DPO.replace("TIME,CH1,CH2", "TIME"), "names no channel"),
    ("a,b\n1,2\n", "neither Tektronix CSV layout"),
])
def test_malformed_csv(tmp_path, text, message):
    p = tmp_path / "bad.csv"
    p.write_text(text)
    with pytest.raises(InstrumentError, match=message):
        read_csv(p)
