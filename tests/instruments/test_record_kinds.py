"""Every reader of every format family (CSV, ISF, WFM) tells from the header what a record
is before it reads a sample: a digital, IQ, spectrum, RF, floating-point or FastFrame record
is refused naming what it is, never imported as volts and never refused for its byte width
(a 4-byte RF spectrum is a spectrum, not a damaged 1-or-2-byte file). Files built to each
layout the manuals and Tektronix's own writer give."""
import struct

import numpy as np
import pytest
from tektronix_reader import write_digital

from instruments.errors import InstrumentError
from instruments.formats import read_waveforms
from instruments.formats.isf import isf_bytes
from instruments.records import Preamble, Waveform

# a 4/5/6 Series CSV's header as Tektronix's writer lays it out
CSV_HEAD = ["Model,MSO54", "Waveform Type,{type}", "Zero Index,40.0", "Sample Interval,1e-06", "Record Length,8",
            "Horizontal Units,s"]


def _csv(tmp_path, name, head_rows, title, columns):
    rows = [",".join(["TIME", *title])]
    rows += [",".join([f"{(k - 40) * 1e-6:.8e}", *(str(c[k]) for c in columns)]) for k in range(8)]
    p = tmp_path / name
    p.write_text("\n".join([*head_rows, "", "Labels," + "," * len(title), *rows]) + "\n")
    return p


def _isf(tmp_path, name, fields: str, width=1, points=100):
    pre = Preamble(points=points, x_increment=1e-6, x_zero=-1e-5, trigger_index=10, y_multiplier=0.01,
                   y_offset=0.0, y_zero=0.0, byte_count=width)
    data = isf_bytes(Waveform("CH1", pre, codes=np.zeros(points, dtype=np.int8 if width == 1 else np.int16)))
    head, _, curve = data.partition(b":CURVE ")
    for change in fields.split(";"):
        key, _, value = change.partition(" ")
        if f";{key} ".encode() in head:
            start = head.index(f";{key} ".encode()) + 1
            head = head[:start] + f"{key} {value}".encode() + head[head.index(b";", start):]
        else:
            head = head.rstrip(b";") + f";{key} {value};".encode()
    if width == 4:  # the curve as 4-byte values: the block's length says so
        curve = f"#{len(str(4 * points))}{4 * points}".encode() + np.zeros(points, ">f4").tobytes() + b"\n"
    p = tmp_path / name
    p.write_bytes(head + b":CURVE " + curve)
    return p


CASES = {
    "csv digital (Waveform Type)": (lambda t: _csv(t, "d.csv", [r.format(type="DIGITAL") for r in CSV_HEAD]
                                                   + ["Digital Type,8x1"], [f"CH1_D{b}" for b in range(8)],
                                                   [[0, 1] * 4] * 8), "a digital waveform"),
    "csv digital (columns only)": (lambda t: _csv(t, "d2.csv", [r.format(type="ANALOG") for r in CSV_HEAD[2:]],
                                                  ["D0", "D1"], [[0, 1] * 4] * 2), "a digital waveform"),
    "csv IQ": (lambda t: _csv(t, "iq.csv", [r.format(type="IQ") for r in CSV_HEAD]
                              + ["IQ_centerFrequency,1000000000.0", "IQ_span,1000000.0", "IQ_fftLength,1024"],
                              ["CH1"], [list(range(8))]), "an IQ waveform"),
    "csv IQ (keys only)": (lambda t: _csv(t, "iq2.csv", [r.format(type="ANALOG") for r in CSV_HEAD]
                                          + ["IQ_centerFrequency,1e9", "IQ_span,1e6"], ["CH1"], [list(range(8))]),
                           "an IQ waveform"),
    "isf RF spectrum, 4-byte floats": (lambda t: _isf(t, "rf.isf", 'BYT_NR 4;BIT_NR 32;BN_FMT FP;XUNIT "Hz";'
                                                      'YUNIT "W";DOMAIN FREQUENCY;WFMTYPE RF_FD', width=4),
                                       "a frequency-domain record"),
    "isf RF time domain": (lambda t: _isf(t, "rftd.isf", "DOMAIN TIME;WFMTYPE RF_TD"), "an RF trace"),
    "isf digital (WFMTYPE)": (lambda t: _isf(t, "dig.isf", "WFMTYPE DIGITAL"), "a digital waveform"),
    "isf digital (source)": (lambda t: _isf(t, "d0.isf", 'WFID "D0, unknown coupling, 100.0us/div, 100 points, '
                                                         'Digital mode"'), "a digital waveform"),
    "isf floating point": (lambda t: _isf(t, "fp.isf", "BYT_NR 4;BIT_NR 32;BN_FMT FP;DOMAIN TIME;WFMTYPE ANALOG",
                                          width=4), "floating-point values"),
    "isf FastFrame": (lambda t: _isf(t, "ff.isf", "NR_FR 10"), "a FastFrame waveform set"),
}


@pytest.mark.parametrize("case", list(CASES))
def test_a_record_that_is_not_analog_volts_is_refused_naming_what_it_is(tmp_path, case):
    make, what = CASES[case]
    path = make(tmp_path)
    with pytest.raises(InstrumentError) as err:
        read_waveforms(path)
    said = str(err.value)
    assert what in said and said.startswith(str(path)) and "\n" not in said, said
    assert "bytes per point" not in said and "BYT_NR = 4" not in said, said


def test_an_analog_isf_of_every_kind_field_still_reads(tmp_path):
    """The fields a DPO/MDO header adds (DOMAIN TIME, WFMTYPE ANALOG, NR_FR 1) are an
    analog record's: it reads, with its screen (VSCALE, VPOS) kept as a CSV's is."""
    path = _isf(tmp_path, "a.isf", "DOMAIN TIME;WFMTYPE ANALOG;NR_FR 1;VSCALE 5.0000E-2;VPOS -1.5;VOFFSET 0.0E+0")
    (w,) = read_waveforms(path)
    assert w.preamble.points == 100
    assert (w.preamble.extra["volts_per_div"], w.preamble.extra["position_div"]) == (0.05, -1.5)


def test_tektronix_own_digital_csv_and_wfm_are_refused_alike(tmp_path):
    paths = [tmp_path / "digital.csv", tmp_path / "digital.wfm"]
    write_digital(*paths)
    for path in paths:
        with pytest.raises(InstrumentError, match="a digital waveform"):
            read_waveforms(path)


def test_a_wfm_spectrum_of_four_byte_values_is_named_before_its_width(realdata, tmp_path):
    data = bytearray((realdata / "tekpce_sample_1.wfm").read_bytes())
    data[15] = 4  # bytes per point: float32
    data[508:511] = b"Hz\0"  # WFM#002/#003: the implicit dimension's units
    p = tmp_path / "fft.wfm"
    p.write_bytes(bytes(data))
    with pytest.raises(InstrumentError, match="a frequency-domain record"):
        read_waveforms(p)
    data[508:511] = b"s\0\0"
    data[122:126] = struct.pack("<i", 6)  # a digital data type, four bytes a point
    p.write_bytes(bytes(data))
    with pytest.raises(InstrumentError, match="a digital waveform"):
        read_waveforms(p)


def test_an_isf_screen_from_its_wfid_takes_the_position_its_scaling_implies(tmp_path):
    """A TDS header names V/div in its WFID only: the position is YOFF codes of the
    25 codes a division (code 0 at the screen's centre) and the offset YZERO, as the CSV
    export writes them, so that a volts record's rail check sees the screen the scope had."""
    path = _isf(tmp_path, "tds.isf", 'WFID "Ch1, DC coupling, 50.00mV/div, 1.000ms/div, 100 points, Sample mode";'
                                    'YMULT 2.0E-3;YOFF 25;YZERO 1.0E-2')
    (w,) = read_waveforms(path)
    e = w.preamble.extra
    assert (e["volts_per_div"], e["vertical_offset_V"], e["position_div"]) == (0.05, 0.01, pytest.approx(1.0))
