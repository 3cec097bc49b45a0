"""Every file in the real-data folder, whatever it is: read exactly as an independent reader
reads it, or refused in one line naming its format. The folder is walked (files added later
are tested by their format, not by name)."""
import struct

import numpy as np
import pytest
from tektronix_reader import read_with_tm_data_types

from instruments.errors import InstrumentError
from instruments.formats import identify, read_waveforms

FOREIGN = ("LeCroy", "Rigol", "Keysight", "Yokogawa", "Rohde", "Siglent", "PicoScope", "HDF5", "no scope format")


def _files(realdata):
    return sorted(p for p in realdata.iterdir() if p.is_file() and not p.name.endswith((".source.txt", ".md")))


def _isf_independent(path):
    """RigolWFM's ISF reader (the first record of a file: it reads no further)."""
    rigol = pytest.importorskip("RigolWFM.wfm")
    ch = rigol.Wfm.from_file(str(path), "ISF").channels[0]
    return [(np.asarray(ch.times), np.asarray(ch.volts))], 1e-6, 1e-9  # it scales in float32


def _csv_independent(path):
    """numpy on the data rows: the DPO/MSO/TBS layout's columns after its TIME row, or the
    TDS1000/2000 layout's fourth and fifth columns of every six-column block (one block per
    channel, side by side). Scopes print times with a float32's digits (or nine): the printed
    column lies within a float32's spacing at the largest time of the uniform grid the header
    gives."""
    lines = path.read_text().splitlines()
    title = next((i for i, line in enumerate(lines) if line.split(",")[0].strip().upper() == "TIME"), None)
    if title is None:
        blocks = (len(lines[0].split(",")) + 1) // 6
        table = np.loadtxt(lines, delimiter=",", usecols=[6 * b + c for b in range(blocks) for c in (3, 4)], ndmin=2)
        eps = float(np.spacing(np.float32(np.max(np.abs(table[:, 0])))))
        return [(table[:, 2 * b], table[:, 2 * b + 1]) for b in range(blocks)], 0.0, eps
    ncol = len([c for c in lines[title].split(",") if c.strip()])
    table = np.loadtxt([line for line in lines[title + 1:] if line.strip()], delimiter=",",
                       usecols=range(ncol), ndmin=2)
    eps = float(np.spacing(np.float32(np.max(np.abs(table[:, 0])))))
    return [(table[:, 0], table[:, k]) for k in range(1, ncol)], 0.0, eps


def _wfm_independent(path):
    """The WFM#003 header fields at their fixed offsets (Tektronix's reference manual for the
    WFM#002/#003 layout, little-endian files): the explicit dimension's scale and offset (V
    per code, V) at bytes 168 and 176, the implicit dimension's (s per sample, s) at 488 and
    496, the curve buffer's byte offset at 16 and the data start / postcharge start offsets
    within it at 822 and 826."""
    b = path.read_bytes()
    assert b[:2] == b"\x0f\x0f" and b[2:10] in (b":WFM#002", b":WFM#003"), "a little-endian WFM#002/3 file"
    (curve,) = struct.unpack_from("<i", b, 16)
    (vscale, voff) = struct.unpack_from("<2d", b, 168)
    (tscale, toff) = struct.unpack_from("<2d", b, 488)
    start, stop = struct.unpack_from("<2I", b, 822)
    width = b[15]
    codes = np.frombuffer(b, dtype={1: "<i1", 2: "<i2"}[width], count=(stop - start) // width, offset=curve + start)
    return [(toff + tscale * np.arange(codes.size), codes * vscale + voff)], 0.0, 0.0


INDEPENDENT = {"isf": _isf_independent, "csv": _csv_independent, "wfm": _wfm_independent}
# what a Tektronix file may hold that is no time record of analog samples, as its refusal names it
NOT_A_TIME_RECORD = ("a frequency-domain record", "not a time record", "a digital waveform", "an IQ waveform",
                     "a FastFrame waveform set")


def test_every_real_file_reads_exactly_or_is_refused_naming_its_format(realdata):
    read, refused = [], []
    for path in _files(realdata):
        try:
            kind = identify(path)
        except InstrumentError as exc:
            msg = str(exc)
            assert "\n" not in msg and msg.startswith(str(path)) and any(f in msg for f in FOREIGN), msg
            assert "the rig reads Tektronix ISF, CSV and WFM files" in msg
            refused.append(path.name)
            continue
        try:
            waves = read_waveforms(path)
        except InstrumentError as exc:  # a Tektronix file holding no analog time record: said so
            msg = str(exc)
            assert "\n" not in msg and msg.startswith(str(path)) and any(f in msg for f in NOT_A_TIME_RECORD), msg
            refused.append(path.name)
            continue
        channels, tol, t_tol = INDEPENDENT[kind](path)
        # every channel the file holds, no more (RigolWFM reads an ISF file's first record only)
        assert len(waves) == len(channels) or (kind == "isf" and len(waves) > len(channels)), path.name
        for w, (t_ref, v_ref) in zip(waves, channels):
            assert w.preamble.points == t_ref.size, path.name
            np.testing.assert_allclose(w.time(), t_ref, rtol=0, atol=1e-6 * w.preamble.x_increment + t_tol,
                                       err_msg=path.name)
            scale = np.max(np.abs(v_ref)) or 1.0
            np.testing.assert_allclose(w.volts(), v_ref, rtol=0, atol=tol * scale + 1e-12 * scale,
                                       err_msg=path.name)
        read.append(path.name)
    assert read and refused


def test_both_channels_of_a_two_channel_tds_csv_read_against_numpy(realdata):
    """TDS2000C/TBS1000B: CH1 and CH2 as two six-column blocks side by side; each channel's
    times and volts are numpy's reading of its block's fourth and fifth columns."""
    path = realdata / "acruz_TDS2000C_2ch_ROD_PIEZO_1.csv"
    ch1, ch2 = read_waveforms(path)
    assert (ch1.channel, ch2.channel) == ("CH1", "CH2")
    table = np.loadtxt(path, delimiter=",", usecols=(3, 4, 9, 10))
    for w, (t, v) in ((ch1, table[:, :2].T), (ch2, table[:, 2:].T)):
        assert w.preamble.points == 2500 and w.preamble.x_increment == 1e-6 and w.preamble.y_unit == "V"
        # the file's times carry a float32's digits (spacing 1.2e-10 s at 1.6 ms): 1e-4 of a sample
        np.testing.assert_allclose(w.time(), t, rtol=0, atol=1e-4 * 1e-6)
        assert np.array_equal(w.volts(), v)
    assert not np.array_equal(ch1.volts(), ch2.volts())  # two channels, not CH1 twice
    assert ch1.preamble.trigger_index == ch2.preamble.trigger_index == 880  # "Trigger Point,880.000009095"


def test_an_fft_csv_is_refused_as_a_frequency_domain_record(realdata):
    with pytest.raises(InstrumentError, match=r"a frequency-domain record .*Horizontal Units = 'Hz'") as exc:
        read_waveforms(realdata / "acruz_TDS_MATH_FFT_TEK0000.CSV")
    assert "\n" not in str(exc.value)


def test_a_digital_wfm_is_refused_as_digital(realdata):
    with pytest.raises(InstrumentError, match=r"a digital waveform \(WFM data type = 6\)"):
        read_waveforms(realdata / "tmdt_digital_waveform.wfm")


def test_other_makers_real_files_are_named(realdata):
    for name, maker in (("jonas_rigol_DS1000Z_NewFile1.csv", "a Rigol CSV export"),
                        ("merz_siglent_SDS1000X_usr_wf_data_0.bin", "a Siglent SDS .bin waveform"),
                        ("rigolwfm_DS1054Z-A.csv", "a Rigol CSV export"),
                        ("rigolwfm_lecroy_3.trc", "a LeCroy .trc waveform")):
        with pytest.raises(InstrumentError, match=maker):
            identify(realdata / name)


def test_the_source_channel_comes_from_the_header(realdata):
    (math,) = read_waveforms(realdata / "jeremitu_data1.isf")  # WFID "Math, AC coupling, ..."
    (ch2,) = read_waveforms(realdata / "tek_16bit_dpo.isf")  # WFID "Ch2, DC coupling, ..."
    assert (math.channel, ch2.channel) == ("MATH", "CH2")
    assert [w.channel for w in read_waveforms(realdata / "bee331_MSO3012_tek0000.csv")] == ["CH1", "CH2"]
    assert [w.channel for w in read_waveforms(realdata / "pchem_TDS2001C_F0000CH1.CSV")] == ["CH1"]  # "Source,CH1"


def test_an_envelope_record_reads_as_min_max_pairs(realdata):
    (w,) = read_waveforms(realdata / "jeremitu_data1.isf")  # PT_FMT ENVELOPE, Pk Detect mode
    assert w.preamble.point_format == "ENV"
    t, lo, hi = w.envelope()
    v = w.volts()
    assert t.size == v.size // 2 == 5000
    assert np.array_equal(lo, np.minimum(v[0::2], v[1::2])) and np.array_equal(hi, np.maximum(v[0::2], v[1::2]))
    # "1.0E-3 s/div, 10000 points": ten divisions hold NR_PT values at XINCR apart
    assert w.preamble.points * w.preamble.x_increment == pytest.approx(10 * 1e-3)
    assert t[1] - t[0] == pytest.approx(2 * w.preamble.x_increment)
    with pytest.raises(ValueError, match="not an envelope"):
        read_waveforms(realdata / "tek_16bit_dpo.isf")[0].envelope()


def test_tektronix_wfm_reads_as_codes_with_their_scaling(realdata):
    (w,) = read_waveforms(realdata / "tekpce_sample_1.wfm")  # Tektronix's own sample file
    assert w.codes.dtype == np.int8 and w.preamble.points == 1000
    assert w.preamble.x_increment == pytest.approx(20e-12) and w.time()[0] == pytest.approx(-10e-9)
    assert (w.codes.min(), w.codes.max()) == (-83, 99)  # a sine-like record, not a constant


def test_tektronix_wfm_agrees_with_tektronix_own_reader_in_its_own_interpreter(realdata):
    path = realdata / "tekpce_sample_1.wfm"
    (w,) = read_waveforms(path)
    (theirs,) = read_with_tm_data_types([path])
    assert np.array_equal(theirs["codes"], w.codes) and theirs["spacing"] == w.preamble.y_multiplier
    assert np.max(np.abs(theirs["t"] - w.time())) < 1e-6 * w.preamble.x_increment


@pytest.mark.parametrize("head, name", [
    (b"#9000020746WAVEDESC\0\0\0\0\0\0\0\0LECROY_2_3\0", "LeCroy .trc"),
    (b"AG10" + bytes(40), "Keysight/Agilent .bin"),
    (b"\xa5\xa5\x00\x00" + bytes(300), "Rigol .wfm"),
    (b"RG03" + bytes(40), "Rigol .bin"),
    (b"X,CH1,CH2,Start,Increment,\nSequence,Volt,Volt,-3e-07,5e-10\n0,1,2,\n", "Rigol CSV"),
    (b"$PublicInfo\nFormatVersion 1.11\n", "Yokogawa"),
    (b"CH1,CH2,Start,Increment,\nVolt,Volt,-6.00000e-02,1.00000e-04\n3.2e-01,1.28e+01,\n", "Rigol CSV"),
    (b"X,CH1,\nSecond,Volt,\n-6.0e-03,0.12,\n", "Rigol CSV"),
    (b"Time,Channel A\n(ms),(V)\n\n-0.5,0.01\n", "PicoScope CSV"),
    (b"PK\x03\x04" + bytes(60), "PicoScope .psdata"),
    (b'<?xml version="1.0"?><Database><Prop Name="Source" Value="eRS_SIGNAL_SOURCE_C1W1"/>', "Rohde & Schwarz"),
    (struct.pack("<2I", 4, 10) + bytes(40), "Rohde & Schwarz .Wfm.bin"),
    (struct.pack("<4I", 1, 0, 1, 0) + struct.pack("<dII", 0.5, 8, 0) * 4 + bytes(40), "Siglent SDS .bin"),
    (b"\x89HDF\r\n\x1a\n" + bytes(100), "HDF5"),
    (b"just some notes\nabout a shot\n", "a text file in no scope format"),
    (b"\x00\x01\x02\x03binary junk" * 10, "a binary file in no scope format"),
])
@pytest.mark.parametrize("suffix", [".isf", ".csv", ".wfm", ""])
def test_other_formats_are_refused_by_content_naming_them(tmp_path, head, name, suffix):
    path = tmp_path / f"record{suffix}"
    path.write_bytes(head)
    with pytest.raises(InstrumentError, match=name.replace(".", r"\.").replace("(", r"\(")) as exc:
        read_waveforms(path)
    assert "\n" not in str(exc.value)


def test_an_empty_file_is_refused(tmp_path):
    (tmp_path / "empty.csv").write_bytes(b"")
    with pytest.raises(InstrumentError, match="empty file"):
        read_waveforms(tmp_path / "empty.csv")
