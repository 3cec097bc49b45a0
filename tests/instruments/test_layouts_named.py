"""Files a user hands over that are not in the scope's own binary or CSV layouts: other
makers' CSV exports named as what they are, an ASCII-encoded ISF read, a header whose
encoding contradicts its curve refused, a BOM before a Tektronix CSV dropped, and a
spreadsheet's semicolon/decimal-comma re-save named as such."""
import numpy as np
import pytest

from instruments.errors import InstrumentError
from instruments.formats import identify, read_waveforms
from instruments.formats.isf import isf_bytes
from instruments.records import Preamble, Waveform

SIGLENT = ("Record Length,Analog:1400,\nSample Interval,Analog:1.00E-06,\nVertical Units,Analog:V,\n"
           "Vertical Scale,Analog:0.5,\nHorizontal Units,S,\nSecond,Volt,\n-7.0E-04,0.02,\n-6.99E-04,0.04,\n")
LECROY = ("LECROYWS3024,23052,Waveform\nSegments,1,SegmentSize,1002\nSegment,TrigTime,TimeSinceSegment1\n"
          "#1,25-Nov-2026 10:00:00,0\nTime,Ampl\n-5e-06,0.001\n-4.99e-06,0.002\n")
LECROY_NO_BANNER = "Segments,1,SegmentSize,1002\nSegment,TrigTime,TimeSinceSegment1\n#1,x,0\nTime,Ampl\n0,1\n"


@pytest.mark.parametrize("text,name", [(SIGLENT, "a Siglent CSV export"), (LECROY, "a LeCroy CSV export"),
                                       (LECROY_NO_BANNER, "a LeCroy CSV export")])
def test_other_makers_csv_exports_are_named(tmp_path, text, name):
    # before: Siglent read like a damaged Tektronix file, LeCroy "a text file in no scope format"
    p = tmp_path / "wave.csv"
    p.write_text(text)
    with pytest.raises(InstrumentError, match=f"{p}: {name}; the rig reads Tektronix"):
        identify(p)


def _wave(n=50, byte_count=1):
    codes = np.round(100 * np.sin(np.arange(n) / 5)).astype(np.int8 if byte_count == 1 else np.int16)
    pre = Preamble(points=n, x_increment=1e-6, x_zero=-1e-5, trigger_index=10, y_multiplier=0.01,
                   y_offset=0.0, y_zero=0.0, byte_count=byte_count)
    return Waveform("CH1", pre, codes=codes)


def _ascii_isf(w) -> bytes:
    """The ISF bytes of ``w`` with an ASCII curve (ENCDG ASC), as CURVE? answers in ASCII."""
    binary = isf_bytes(w)
    head = binary[:binary.index(b":CURVE ")].replace(b"ENCDG BIN", b"ENCDG ASC")
    return head + b":CURVE " + ",".join(str(int(c)) for c in w.codes).encode() + b"\n"


@pytest.mark.parametrize("byte_count", [1, 2])
def test_an_ascii_isf_reads_the_codes_it_lists(tmp_path, byte_count):
    w = _wave(byte_count=byte_count)
    p = tmp_path / "a.isf"
    p.write_bytes(_ascii_isf(w) * 2)  # two records back to back
    assert identify(p) == "isf"
    first, second = read_waveforms(p)  # had been "no :CURVE block after byte 0 (not an ISF file?)"
    for back in (first, second):
        assert np.array_equal(back.codes, w.codes) and back.codes.dtype == w.codes.dtype
        assert np.allclose(back.volts(), w.volts()) and back.preamble.x_zero == pytest.approx(-1e-5)


def test_an_encoding_that_contradicts_the_curve_is_refused(tmp_path):
    w = _wave()
    p = tmp_path / "asc_over_bin.isf"
    p.write_bytes(isf_bytes(w).replace(b"ENCDG BIN", b"ENCDG ASCII"))
    with pytest.raises(InstrumentError, match=r"header says ENCDG ASCII \(ASCII codes\) over a binary '#' block"):
        read_waveforms(p)  # had been read as binary silently
    q = tmp_path / "bin_over_asc.isf"
    q.write_bytes(_ascii_isf(w).replace(b"ENCDG ASC", b"ENCDG BIN"))
    with pytest.raises(InstrumentError, match=r"ENCDG BIN \(binary\) over a curve that is no '#' block"):
        read_waveforms(q)
    r = tmp_path / "short.isf"
    r.write_bytes(_ascii_isf(w).replace(b",5", b",x5", 1))
    with pytest.raises(InstrumentError, match="not a whole-number code"):
        read_waveforms(r)


def test_a_tektronix_csv_after_a_byte_order_mark_reads_as_without(tmp_path, realdata):
    src = realdata / "accel_TEK00000.CSV"
    p = tmp_path / "bom.csv"
    p.write_bytes(b"\xef\xbb\xbf" + src.read_bytes())  # before: "a text file in no scope format"
    (w,), (ref,) = read_waveforms(p), read_waveforms(src)
    assert np.array_equal(w.volts(), ref.volts()) and np.array_equal(w.time(), ref.time())


def test_a_semicolon_decimal_comma_resave_is_named(tmp_path, realdata):
    text = (realdata / "accel_TEK00000.CSV").read_text()
    resaved = "\n".join(line.replace(",", ";").replace(".", ",") for line in text.splitlines())
    p = tmp_path / "resaved.csv"
    p.write_text(resaved)
    with pytest.raises(InstrumentError, match="semicolon-separated CSV with decimal commas .a spreadsheet's re-save"):
        read_waveforms(p)
