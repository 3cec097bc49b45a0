"""The CSV export as a 4/5/6 Series scope writes it: one file per channel, a fractional Zero
Index, read back to the sample by this project's reader, by numpy and by Tektronix's own
reader (tm_data_types, in its own interpreter: it pins numpy < 2)."""
import numpy as np
import pytest
from tektronix_reader import read_with_tm_data_types

from instruments.formats import read_record, read_waveforms
from instruments.formats.tek_csv import write_csv
from instruments.records import Preamble, Waveform

DT = 8e-8
FRACTION = 0.37  # the first sample lies 500.37 samples before the trigger: off the sample grid


def _shot():
    """Two channels on one time base whose first sample is not on the trigger's grid."""
    pre = dict(points=2000, x_increment=DT, x_zero=-(500 + FRACTION) * DT, trigger_index=500, y_multiplier=0.004,
               y_offset=3.0, byte_count=1, extra={"probe": 10, "volts_per_div": 0.1, "position_div": 0.75})
    codes = (np.arange(2000) % 200 - 100).astype(np.int8)
    return {"CH1": Waveform("CH1", Preamble(y_zero=0.01, waveform_id="CH1, DC coupling, 0.1V/div", **pre), codes=codes),
            "CH2": Waveform("CH2", Preamble(y_zero=-0.2, waveform_id="", **pre), codes=codes[::-1].copy())}


def _header(path) -> dict:
    lines = path.read_text().splitlines()
    return dict(line.split(",", 1) for line in lines[:lines.index(next(x for x in lines if x.startswith("TIME,")))]
                if line)


def test_one_file_per_channel_in_the_four_five_six_series_layout(tmp_path):
    shot = _shot()
    paths = write_csv(shot, tmp_path, "shot")
    assert [p.name for p in paths] == ["shot_CH1.csv", "shot_CH2.csv"]
    head = _header(paths[0])
    assert "Model" not in head  # the virtual scope's model (a TDS) writes another layout: none is named
    assert head["Waveform Type"] == "ANALOG" and head["Horizontal Units"] == "s" and head["Record Length"] == "2000"
    assert float(head["Zero Index"]) == pytest.approx(500 + FRACTION, abs=1e-9)
    assert head["Label"] == "CH1; DC coupling; 0.1V/div"
    assert paths[1].read_text().splitlines()[-2001] == "TIME,CH2"


def test_our_export_reads_back_to_a_millionth_of_a_sample(tmp_path):
    shot = _shot()
    paths = write_csv(shot, tmp_path, "shot")
    record = read_record(paths)
    assert list(record.waveforms) == ["CH1", "CH2"]
    for ch, w in shot.items():
        back = record[ch]
        table = np.loadtxt(paths[list(shot).index(ch)], delimiter=",", skiprows=17)
        for t in (back.time(), table[:, 0]):  # our reader, and numpy on the TIME column
            assert np.max(np.abs(t - w.time())) < 1e-6 * DT
        for v in (back.volts(), table[:, 1]):  # volts to 10 digits: a millionth of a code
            assert np.max(np.abs(v - w.volts())) < 1e-6 * w.preamble.y_multiplier
        assert back.preamble.trigger_index == 500


def test_tektronix_own_reader_puts_every_sample_where_we_do(tmp_path):
    shot = _shot()
    paths = write_csv(shot, tmp_path, "shot")
    theirs = read_with_tm_data_types(paths)
    assert [t["source"] for t in theirs] == ["CH1", "CH2"]  # one waveform per channel, each named
    for w, t in zip(shot.values(), theirs):
        assert t["zero_index"] == pytest.approx(500 + FRACTION, abs=1e-9)
        assert np.max(np.abs(t["t"] - w.time())) < 1e-6 * DT
        # tm_data_types keeps volts as int16 codes over the record's span
        assert np.max(np.abs(t["v"] - w.volts())) < np.ptp(w.volts()) / 65535


def test_tektronix_own_reader_reads_a_real_four_five_six_series_csv_as_we_do(realdata):
    path = realdata / "tmdt_MSO64_analog_waveform.csv"
    (ours,) = read_waveforms(path)
    (theirs,) = read_with_tm_data_types([path])
    assert theirs["source"] == ours.channel == "REF7"
    assert np.max(np.abs(theirs["t"] - ours.time())) < 1e-6 * ours.preamble.x_increment


def test_a_read_real_record_exports_and_reads_back(realdata, tmp_path):
    (ref7,) = read_waveforms(realdata / "tmdt_MSO64_analog_waveform.csv")  # Zero Index 24999.16015625
    (path,) = write_csv({"REF7": ref7}, tmp_path, "again")
    assert float(_header(path)["Zero Index"]) == pytest.approx(24999.16015625, abs=1e-6)
    (back,) = read_waveforms(path)
    assert np.max(np.abs(back.time() - ref7.time())) < 1e-6 * ref7.preamble.x_increment
    assert np.array_equal(back.volts(), ref7.volts())
