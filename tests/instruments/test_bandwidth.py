"""A bandwidth limit whose rise time is a large part of the pulse's width lowers, widens
and delays the pulse: the analysis gives no figure from it and says why, for a virtual
record (its channel settings) and a real file (the header's filter frequency) alike."""

import re

import numpy as np
import pytest

from instruments.analysis import GaugeSetup, Setup, analyze_record
from instruments.analysis.distortion import too_slow
from instruments.formats import read_waveforms
from instruments.formats.isf import isf_bytes
from instruments.records import Preamble, ScopeRecord, Waveform

DT = 2e-7
SETUP = Setup(GaugeSetup("CH1", 0.0, 0.05), GaugeSetup("CH2", 0.0427, 0.05))


def _record(bandwidth_Hz) -> ScopeRecord:
    """Two 28 us FWHM pulses (12 us standard deviation) 190 us apart, 8-bit, with the
    channels' bandwidth limit in their preambles (None: none)."""
    t = DT * (np.arange(4000) - 500)
    waves = {}
    for ch, at in (("CH1", 1e-4), ("CH2", 2.9e-4)):
        codes = np.rint(100 * np.exp(-0.5 * ((t - at) / 12e-6) ** 2)).astype(np.int8)
        pre = Preamble(points=t.size, x_increment=DT, x_zero=float(t[0]), trigger_index=500, y_multiplier=2e-3,
                       y_offset=0.0, y_zero=0.0, extra={"bandwidth_Hz": bandwidth_Hz})
        waves[ch] = Waveform(ch, pre, codes=codes)
    return ScopeRecord(waves, True)


def test_a_bandwidth_slower_than_a_third_of_the_pulse_gives_no_figure():
    fwhm = 2.3548 * 12e-6
    slowest_allowed = 0.35 / (fwhm / 3)  # 37 kHz
    ok = analyze_record(_record(1.05 * slowest_allowed), SETUP)
    assert ok.speed_m_per_s == pytest.approx(0.0427 / 1.9e-4, rel=0.01) and ok.amplitude_N is not None
    rep = analyze_record(_record(0.95 * slowest_allowed), SETUP)
    assert rep.speed_m_per_s is None and rep.amplitude_N is None
    why = rep.reasons["amplitude_N"]
    assert why.startswith("CH1: its bandwidth limit of") and "; CH2: its bandwidth limit of" in why
    assert re.search(r"more than 1/3 of the measured pulse's FWHM \(2\.8\de-05 s\)", why), why
    assert analyze_record(_record(None), SETUP).speed_m_per_s is not None  # no limit known: no doubt


def test_the_rule_in_numbers():
    assert too_slow("CH1", 1e3, 61e-6).startswith("CH1: its bandwidth limit of 1000 Hz rises in 0.35/B = 0.00035 s")
    assert too_slow("CH1", 20e6, 61e-6) == "" and too_slow("CH1", None, 61e-6) == ""
    assert too_slow("CH1", 1e3, float("nan")) == ""


def test_a_files_filter_frequency_reaches_the_analysis(tmp_path, realdata):
    (csv,) = read_waveforms(realdata / "accel_TEK00000.CSV")  # Filter Frequency,2e+08
    assert csv.preamble.extra["bandwidth_Hz"] == 2e8
    first, _ = read_waveforms(realdata / "tek_8bit_two_records.isf")  # FILTERF 100000000
    assert first.preamble.extra["bandwidth_Hz"] == 1e8
    paths = []
    for ch, w in _record(None).waveforms.items():
        p = tmp_path / f"{ch}.isf"
        p.write_bytes(isf_bytes(w).replace(b":CURVE", b"FILTERF 1.0E+3;:CURVE"))
        paths.append(p)
    record = ScopeRecord({w.channel: w for p in paths for w in read_waveforms(p)}, True)
    assert "bandwidth limit of 1000 Hz" in analyze_record(record, SETUP).reasons["speed_m_per_s"]
