"""Scope-file readers: real Tektronix files, both CSV layouts, and malformed files."""
import re
import struct

import numpy as np
import pytest

from instruments.errors import InstrumentError
from instruments.formats import read_csv, read_isf, read_waveforms
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
    (DPO.replace("Zero Index,2", "Zero Index,7"), "Zero Index = 7 and Sample Interval = 1e-06 put the first sample"),
    ("a,b\n1,2\n", "neither Tektronix CSV layout"),
])
def test_malformed_csv(tmp_path, text, message):
    p = tmp_path / "bad.csv"
    p.write_text(text)
    with pytest.raises(InstrumentError, match=message):
        read_csv(p)


def _tds_blocks(channels, n=5, dt=1e-6, trigger=2.5):
    """A TDS1000/2000 / TBS1000B CSV holding ``channels`` side by side: per channel a six-column
    block (header name, value, unit, time, volts, empty), as the TDS2000C writes them."""
    header = [("Record Length", str(n), "Points"), ("Sample Interval", f"{dt:e}", "s"),
              ("Trigger Point", str(trigger), "Samples"), ("", "", ""), ("", "", ""), ("", "", ""),
              ("Source", "{ch}", ""), ("Vertical Units", "Volts", ""), ("Horizontal Units", "s", "")]
    lines = []
    for i in range(n):
        name, value, unit = header[i] if i < len(header) else ("", "", "")
        t = (i - trigger) * dt
        lines.append(",".join(f"{name},{value.format(ch=ch)},{unit},{t:.9e},{0.1 * k + 0.01 * i:.4f},"
                              for k, ch in enumerate(channels)))
    return "\n".join(lines) + "\n"


@pytest.mark.parametrize("channels", [("CH1",), ("CH1", "CH2"), ("CH1", "CH2", "CH3"), ("CH1", "CH2", "CH3", "CH4")])
def test_every_tds_block_is_a_channel(tmp_path, channels):
    p = tmp_path / "tds.csv"
    p.write_text(_tds_blocks(channels, n=12))
    waves = read_csv(p)
    assert [w.channel for w in waves] == list(channels)
    for k, w in enumerate(waves):
        assert np.allclose(w.volts(), 0.1 * k + 0.01 * np.arange(12), rtol=0, atol=1e-12)
        assert np.allclose(w.time(), (np.arange(12) - 2.5) * 1e-6, rtol=0, atol=1e-15)
        assert w.preamble.y_unit == "V" and w.preamble.trigger_index == 2  # "Volts"; 2.5 -> sample 2


def test_tds_blocks_naming_no_source_are_numbered(tmp_path):
    p = tmp_path / "scope-2.csv"
    p.write_text(_tds_blocks(("CH1", "CH2", "CH3"), n=12).replace("Source,", "Sourc,"))
    assert [w.channel for w in read_csv(p)] == ["SCOPE_2#1", "SCOPE_2#2", "SCOPE_2#3"]


def test_a_tds_block_with_a_short_record_names_its_column(tmp_path):
    lines = _tds_blocks(("CH1", "CH2"), n=12).splitlines()
    lines[0] = lines[0].replace(",Record Length,12,", ",Record Length,13,")  # the second block's
    p = tmp_path / "tds.csv"
    p.write_text("\n".join(lines) + "\n")
    with pytest.raises(InstrumentError, match="Record Length says 13 points but the file holds 12 \\(column 7\\)"):
        read_csv(p)


@pytest.mark.parametrize("unit, what", [("Hz", "a frequency-domain record"), ("div", "not a time record")])
def test_a_record_not_in_seconds_is_refused_in_every_reader(tmp_path, unit, what):
    tds = tmp_path / "tds.csv"
    tds.write_text(_tds_blocks(("MATH",), n=12).replace("Horizontal Units,s", f"Horizontal Units,{unit}"))
    dpo = tmp_path / "dpo.csv"
    dpo.write_text(DPO.replace("Sample Interval", f"Horizontal Units,{unit}\nSample Interval"))
    isf = _isf(tmp_path, isf_bytes(_wave()).replace(b'XUNIT "s"', f'XUNIT "{unit}"'.encode()))
    for path, field in ((tds, "Horizontal Units"), (dpo, "Horizontal Units"), (isf, "XUNIT")):
        with pytest.raises(InstrumentError, match=f"{what}.*: {field} = '{unit}'") as exc:
            read_waveforms(path)
        assert "\n" not in str(exc.value) and str(exc.value).startswith(str(path))


def _wfm(realdata, tmp_path, name, change):
    """Tektronix's sample WFM#003 file with header fields changed (offset -> bytes)."""
    data = bytearray((realdata / "tekpce_sample_1.wfm").read_bytes())
    for offset, value in change.items():
        data[offset:offset + len(value)] = value
    p = tmp_path / name
    p.write_bytes(bytes(data))
    return p


def test_a_fastframe_wfm_is_refused_by_name(realdata, tmp_path):
    # static file info: frames - 1 at byte 72; waveform header: set type 1 (FastFrame) at 78
    p = _wfm(realdata, tmp_path, "ff.wfm", {72: struct.pack("<I", 9), 78: struct.pack("<i", 1)})
    with pytest.raises(InstrumentError, match=r"a FastFrame waveform set \(10 frames, set type = 1\)"):
        read_waveforms(p)


@pytest.mark.parametrize("change, message", [({2: b":WFM#004"}, "WFM version string = b':WFM#004'"),
                                             ({15: b"\x04"}, "WFM bytes per point = 4")])
def test_a_wfm_of_another_version_or_width_is_refused(realdata, tmp_path, change, message):
    with pytest.raises(InstrumentError, match=message):
        read_waveforms(_wfm(realdata, tmp_path, "x.wfm", change))


def test_a_wfm_in_hertz_is_refused_as_a_spectrum(realdata, tmp_path):
    # WFM#002/#003: the implicit dimension's units, char[20] at byte 508
    p = _wfm(realdata, tmp_path, "fft.wfm", {508: b"Hz\0"})
    with pytest.raises(InstrumentError, match="a frequency-domain record .*WFM implicit dimension units = 'Hz'"):
        read_waveforms(p)


def test_an_iq_wfm_is_refused_by_name(realdata, tmp_path):
    # an IQ capture is told by the IQ_ keys of the tekmeta block after the curve
    key = b"IQ_centerFrequency"
    meta = b"tekmeta!" + struct.pack("<I", 1) + struct.pack("<I", len(key)) + key + b"\x03" + struct.pack("<d", 1e9)
    p = tmp_path / "iq.wfm"
    p.write_bytes((realdata / "tekpce_sample_1.wfm").read_bytes() + meta)
    with pytest.raises(InstrumentError, match="an IQ waveform"):
        read_waveforms(p)


def test_an_iq_wfm_written_by_tektronix_own_writer_is_refused_by_name(tmp_path):
    from tektronix_reader import write_iq_wfm

    write_iq_wfm(tmp_path / "iq.wfm")
    with pytest.raises(InstrumentError, match="an IQ waveform"):
        read_waveforms(tmp_path / "iq.wfm")


@pytest.mark.parametrize("data_type, what", [(6, "a digital waveform"),
                                             (5, r"a waveform database \(pixel map\) record"),
                                             (9, "an unknown data type 9")])
def test_a_wfm_of_another_data_type_is_refused_by_name(realdata, tmp_path, data_type, what):
    p = _wfm(realdata, tmp_path, "x.wfm", {122: struct.pack("<i", data_type)})
    with pytest.raises(InstrumentError, match=f"{what} \\(WFM data type = {data_type}\\)"):
        read_waveforms(p)


@pytest.mark.parametrize("name", ["Tek000-ch1.wfm", "shot 3 (copy).wfm", "2024-05-01.wfm"])
def test_any_file_name_gives_a_channel_the_archive_stores(realdata, tmp_path, name):
    from instruments.archive import Archive, Entry
    from instruments.formats import read_record

    p = tmp_path / name
    p.write_bytes((realdata / "tekpce_sample_1.wfm").read_bytes())
    record = read_record([p])
    (channel,) = record.waveforms
    assert re.fullmatch(r"[A-Za-z_][A-Za-z0-9_#]*", channel), channel
    assert record[channel].preamble.extra["name_in_file"] == p.stem  # the name as the file gave it
    (shot,) = Archive(tmp_path / "a.h5").append([Entry(record, False)])
    back = Archive(tmp_path / "a.h5").read(shot).record
    assert np.array_equal(back[channel].volts(), record[channel].volts())


def test_a_picoscope_csv_is_named(tmp_path):
    p = tmp_path / "pico.csv"
    p.write_text("Time,Channel A,Channel B\n(ms),(V),(mV)\n\n-0.5,0.01,2.0\n-0.49,0.02,2.1\n")
    with pytest.raises(InstrumentError, match="a PicoScope CSV export; the rig reads Tektronix"):
        read_waveforms(p)


def test_a_keysight_infiniium_h5_is_named(tmp_path):
    h5py = pytest.importorskip("h5py")
    p = tmp_path / "scope.h5"
    with h5py.File(p, "w") as f:  # Infiniium's layout: /Waveforms/Channel 1 with the samples
        f.create_group("Waveforms").create_dataset("Channel 1", data=np.zeros(10, dtype=np.int16))
    with pytest.raises(InstrumentError, match="a Keysight Infiniium HDF5 waveform"):
        read_waveforms(p)
