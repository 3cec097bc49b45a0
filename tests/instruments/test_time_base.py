"""One time base per record: a header's Sample Interval that contradicts the file's own
TIME column is refused in every CSV layout, and two channels of one shot read from an ISF
and a CSV file share one time base (compared to a millionth of a sample, not as floats),
with one comparison naming the files and their numbers for import and analysis alike."""
import re
from dataclasses import replace

import numpy as np
import pytest

from instruments.analysis import GaugeSetup, Setup, analyze_record
from instruments.errors import InstrumentError
from instruments.formats import check_one_time_base, read_record, read_waveforms
from instruments.formats.isf import isf_bytes
from instruments.formats.tek_csv import write_csv
from instruments.records import Preamble, ScopeRecord, Waveform


@pytest.mark.parametrize("name,old,new", [
    ("accel_TEK00000.CSV", "Sample Interval,0.0008", "Sample Interval,0.0016"),  # TBS1000C
    ("pchem_TDS2001C_F0000CH1.CSV", "Sample Interval,1.00E-09", "Sample Interval,1.01E-09"),  # TDS
    ("bee331_MSO3012_tek0000.csv", "Sample Interval,4e-08", "Sample Interval,4.4e-08"),  # DPO/MSO
])
def test_a_sample_interval_the_time_column_contradicts_is_refused_naming_both(tmp_path, realdata, name, old, new):
    text = (realdata / name).read_text()
    assert old in text
    read_waveforms(realdata / name)  # the file as the scope wrote it reads
    bad = tmp_path / name
    bad.write_text(text.replace(old, new))
    with pytest.raises(InstrumentError) as err:
        read_waveforms(bad)
    said = str(err.value)
    assert str(bad) in said and "\n" not in said
    assert re.search(r"Sample Interval = \S+ put the first sample at .* and the last at .* s, the TIME column at "
                     r".* s and .* s: they must agree", said), said


def test_the_tbs1000c_time_axis_is_the_files_own(realdata):
    (w,) = read_waveforms(realdata / "accel_TEK00000.CSV")
    assert w.time()[-1] == pytest.approx(0.7992, abs=1e-9)  # the TIME column's last time


def _wave(channel: str, x_zero: float) -> Waveform:
    codes = (40 * np.exp(-0.5 * ((np.arange(12500) - 3000.0) / 60) ** 2)).astype(np.int8)
    pre = Preamble(points=12500, x_increment=2e-7, x_zero=x_zero, trigger_index=1250, y_multiplier=2e-3,
                   y_offset=0.0, y_zero=0.0, extra={"volts_per_div": 0.05, "position_div": 0.0})
    return Waveform(channel, pre, codes=codes)


def _files(tmp_path, x_zero_ch2: float) -> list:
    one = tmp_path / "shot_CH1.isf"
    one.write_bytes(isf_bytes(_wave("CH1", -0.000249997804)))
    (two,) = write_csv({"CH2": replace(_wave("CH2", x_zero_ch2), codes=np.roll(_wave("CH2", 0).codes, 950))},
                       tmp_path, "shot")
    return [one, two]


def test_an_isf_and_a_csv_channel_of_one_shot_share_a_time_base(tmp_path):
    # the CSV's first time a few float steps off the ISF's, as printed digits leave it
    read = read_record(_files(tmp_path, -0.000249997804))
    csv = read["CH2"]
    csv = replace(csv, preamble=replace(csv.preamble, x_zero=csv.preamble.x_zero * (1 + 4e-15)))
    record = ScopeRecord({"CH1": read["CH1"], "CH2": csv}, True)
    assert record["CH2"].preamble.x_zero != record["CH1"].preamble.x_zero
    check_one_time_base(record)  # had been "different time bases" with the same numbers printed twice
    rep = analyze_record(record, Setup(GaugeSetup("CH1", 0.0, 0.05), GaugeSetup("CH2", 0.0427, 0.05)))
    assert rep.speed_m_per_s == pytest.approx(0.0427 / (950 * 2e-7), rel=1e-3)


def test_one_sample_apart_is_two_time_bases_named_alike_by_import_and_analysis(tmp_path):
    paths = _files(tmp_path, -0.000249997804 + 2e-7)
    record = read_record(paths)
    with pytest.raises(InstrumentError) as imported:
        check_one_time_base(record)
    with pytest.raises(InstrumentError) as analysed:
        analyze_record(record, Setup(GaugeSetup("CH1", 0.0, 0.05), GaugeSetup("CH2", 0.0427, 0.05)))
    assert str(imported.value) == str(analysed.value)
    said = str(imported.value)
    assert all(str(p) in said for p in paths) and "12500 points at 2e-07 s from -0.000249997804 s" in said
    assert "12500 points at 2e-07 s from -0.000249797804 s" in said
