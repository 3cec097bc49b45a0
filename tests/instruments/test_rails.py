"""A record read from a file whose samples sit at the ADC's rail carries the over-range
flag the virtual scope sets, and the analysis gives no amplitude from it (one rule for
both): codes at the 8-bit rails, at the rails of 16-bit data of an 8-bit converter, and
volts (CSV) in runs at the screen's edge."""
import re

import numpy as np
import pytest

from instruments.analysis import GaugeSetup, Setup, analyze_record
from instruments.formats import read_record, read_waveforms
from instruments.formats.isf import isf_bytes
from instruments.formats.tek_csv import write_csv
from instruments.rails import rail, rail_of_codes, rail_of_volts
from instruments.records import Preamble, Waveform

DT = 2e-7
N = 5000
N_PRE = 500
VOLTS_PER_DIV = 0.05


def _pulse_codes(peak_V: float, at_s: float) -> np.ndarray:
    """An 8-bit record (50 mV/div, 25 codes a division) of a 30 us wide pulse of ``peak_V``
    at ``at_s`` after the trigger, clipped at the converter's rails as a scope clips it."""
    t = DT * (np.arange(N) - N_PRE)
    v = peak_V * np.exp(-0.5 * ((t - at_s) / 12e-6) ** 2)
    return np.clip(np.rint(v / (VOLTS_PER_DIV / 25)), -128, 127).astype(np.int8)


def _wave(channel: str, codes: np.ndarray) -> Waveform:
    pre = Preamble(points=codes.size, x_increment=DT, x_zero=-N_PRE * DT, trigger_index=N_PRE,
                   y_multiplier=VOLTS_PER_DIV / 25, y_offset=0.0, y_zero=0.0,
                   extra={"volts_per_div": VOLTS_PER_DIV, "position_div": 0.0})
    return Waveform(channel, pre, codes=codes)  # no over-range flag: a file carries none


def test_codes_at_the_8bit_rail_flag_an_isf_record_read_back(tmp_path):
    codes = _pulse_codes(0.45, 1e-4)  # 9 N at 0.05 V/N: 0.45 V, 9 divisions
    path = tmp_path / "CH1.isf"
    path.write_bytes(isf_bytes(_wave("CH1", codes)))
    (w,) = read_waveforms(path)
    assert w.overrange and rail(w).top == np.count_nonzero(codes == 127) > 20 and rail(w).bottom == 0
    unclipped = tmp_path / "low.isf"
    unclipped.write_bytes(isf_bytes(_wave("CH1", _pulse_codes(0.2, 1e-4))))  # 4 divisions: on screen
    assert not read_waveforms(unclipped)[0].overrange


def test_16bit_rails_depend_on_the_converter_behind_the_codes():
    eight_bit = (np.array([0, 10, 127, 127, 127, -5, -128]) * 256).astype(np.int16)
    assert rail_of_codes(eight_bit).top == 3 and rail_of_codes(eight_bit).bottom == 1  # 32512 and -32768
    sixteen_bit = np.array([0, 1, 32512, 32512, 32767, -3], np.int16)  # 32512 is not the rail of these
    assert rail_of_codes(sixteen_bit).top == 1 and rail_of_codes(sixteen_bit).longest_run == 1


def test_volts_clip_only_in_a_run_at_the_screens_edge():
    top = 5.08 * 0.05  # 127 codes at 50 mV/div
    flat = np.array([0, 0.1, top, top, top, 0.1, 0.0])
    assert rail_of_volts(flat, 0.05, 0.0, 0.0).top == 3
    assert rail_of_volts(flat, 0.05, 0.0, 0.0).longest_run == 3
    assert rail_of_volts(flat, 0.1, 0.0, 0.0).top == 0  # at 100 mV/div the same top is 2.5 divisions up
    assert rail_of_volts(flat, 0.05, 0.2, 0.0).top == 0  # a 0.2 V offset: the top is 1.08 divisions up
    assert rail_of_volts(flat, 0.05, 0.0, -2.0).top == 0  # the trace 2 divisions down: 3.08 divisions up
    assert rail_of_volts(flat, 0.05, 0.0, 2.0).top == 3  # 7.08 divisions: beyond the screen's top
    two = np.array([0, top, top, 0.1, top, 0.0])
    assert rail_of_volts(two, 0.05, 0.0, 0.0).top == 0  # runs of 2: a quantised peak's top, not a rail
    assert rail_of_volts(-flat, 0.05, 0.0, 0.0).bottom == 3


def test_a_csv_export_of_a_clipped_record_reads_back_clipped(tmp_path):
    (path,) = write_csv({"CH1": _wave("CH1", _pulse_codes(0.45, 1e-4))}, tmp_path, "s")
    (w,) = read_waveforms(path)
    assert w.codes is None and w.overrange and rail(w).top > 20
    (path,) = write_csv({"CH1": _wave("CH1", _pulse_codes(0.2, 1e-4))}, tmp_path / "..", "low")
    assert not read_waveforms(path)[0].overrange


def test_real_csv_files_on_screen_are_not_clipped(realdata):
    # a TDS2001C record at 20 mV/div with a -43.2 mV offset: its 91 mV maximum is 2.4 divisions up
    (w,) = read_waveforms(realdata / "pchem_TDS2001C_F0000CH1.CSV")
    assert not w.overrange
    assert not any(w.overrange for w in read_waveforms(realdata / "bee331_MSO3012_tek0000.csv"))


@pytest.mark.parametrize("fmt", ["isf", "csv"])
def test_the_analysis_of_clipped_files_gives_no_amplitude_and_says_how_many_samples(tmp_path, fmt):
    # before: the flat tops were fitted as pulses, and an amplitude of the cut top came out
    waves = {"CH1": _wave("CH1", _pulse_codes(0.45, 1e-4)), "CH2": _wave("CH2", _pulse_codes(0.45, 2.9e-4))}
    if fmt == "isf":
        paths = []
        for ch, w in waves.items():
            (tmp_path / f"{ch}.isf").write_bytes(isf_bytes(w))
            paths.append(tmp_path / f"{ch}.isf")
    else:
        paths = write_csv(waves, tmp_path, "shot")
    setup = Setup(GaugeSetup("CH1", 0.0, 0.05), GaugeSetup("CH2", 0.0427, 0.05))
    rep = analyze_record(read_record(paths), setup)
    n = int(np.count_nonzero(waves["CH1"].codes == 127))
    assert rep.amplitude_N is None and rep.speed_m_per_s is None
    assert re.match(rf"CH1: clipped: {n} samples at the ADC's top, a flat top of \d+ samples",
                    rep.reasons["amplitude_N"])
    assert "CH2: clipped" in rep.reasons["speed_m_per_s"]
    assert re.search(r"the flat tops leave the peak times uncertain by up to 2\.\d+e-05 s, 1\d% of the 0\.00019 s "
                     r"between the gauges", rep.reasons["speed_m_per_s"])
    # the same pulses on screen give both figures
    low = {ch: _wave(ch, _pulse_codes(0.2, at)) for ch, at in (("CH1", 1e-4), ("CH2", 2.9e-4))}
    for ch, w in low.items():
        (tmp_path / f"low_{ch}.isf").write_bytes(isf_bytes(w))
    ok = analyze_record(read_record([tmp_path / "low_CH1.isf", tmp_path / "low_CH2.isf"]), setup)
    assert ok.speed_m_per_s == pytest.approx(0.0427 / 1.9e-4, rel=0.01) and ok.amplitude_N == pytest.approx(4, rel=0.02)


def test_a_flat_top_short_against_the_flight_still_gives_the_speed_but_no_amplitude(tmp_path):
    # CH1 just reaches code 127 for 13 samples (2.6 us): its peak time is uncertain by 1.3 us,
    # 0.7% of the 190 us flight; the amplitude of a pulse that touched the rail is not known
    paths = []
    for ch, peak, at in (("CH1", 0.2545, 1e-4), ("CH2", 0.2, 2.9e-4)):
        (tmp_path / f"{ch}.isf").write_bytes(isf_bytes(_wave(ch, _pulse_codes(peak, at))))
        paths.append(tmp_path / f"{ch}.isf")
    rep = analyze_record(read_record(paths), Setup(GaugeSetup("CH1", 0.0, 0.05), GaugeSetup("CH2", 0.0427, 0.05)))
    assert rep.speed_m_per_s == pytest.approx(0.0427 / 1.9e-4, rel=0.01)
    assert rep.amplitude_N is None and rep.duration_s is None
    assert re.match(r"CH1: clipped: 1\d samples at the ADC's top", rep.reasons["amplitude_N"])
    assert "CH2" not in rep.reasons["amplitude_N"]
