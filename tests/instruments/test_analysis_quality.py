"""The analysis says when it cannot measure: the signal-to-noise rule against records of known
noise, the plausibility rules, and a reason for every missing figure."""
from dataclasses import replace

import numpy as np
import pytest

from instruments.pipeline import FIGURES, GaugeSetup, Setup, analyze_record
from instruments.quality import baseline_noise
from instruments.records import Preamble, ScopeRecord, Waveform

H = 1e-7
N, PRE = 20000, 4000  # samples; pre-trigger samples
T = (np.arange(N) - PRE) * H
SETUP = Setup(GaugeSetup("CH1", 0.0), GaugeSetup("CH2", 0.0431), bead_diameter_m=4.76e-3)
DELAY = 0.0431 / 200.0  # a 200 m/s pulse


def sech2(t0, amp, width=2e-5):
    return amp / np.cosh(np.clip((T - t0) / width, -300, 300)) ** 2


def wave(name, v, **pre):
    p = Preamble(points=N, x_increment=H, x_zero=T[0], trigger_index=PRE, y_multiplier=1.0, y_offset=0.0,
                 y_zero=0.0, byte_count=0)
    return Waveform(name, replace(p, **pre), samples=v)


def record(amp_sigma, sigma=0.01, seed=1, delay=DELAY, **pre):
    rng = np.random.default_rng(seed)
    up = sech2(2e-4, amp_sigma * sigma) + rng.normal(0, sigma, N)
    low = sech2(2e-4 + delay, amp_sigma * sigma) + rng.normal(0, sigma, N)
    return ScopeRecord({"CH1": wave("CH1", up, **pre), "CH2": wave("CH2", low, **pre)}, True)


def test_the_baseline_noise_is_the_gaussian_sigma_and_blind_to_a_spike():
    v = np.random.default_rng(3).normal(0, 0.02, 5000)
    v[100] = 50.0  # a spike in the baseline moves the standard deviation 35x, the MAD not at all
    # 1.4826 MAD estimates sigma with a relative sd of 1.17/sqrt(n) = 1.7% at n = 5000
    assert baseline_noise(v, 5000) == pytest.approx(0.02, rel=0.06)


def test_the_noise_never_falls_below_quantisation():
    assert baseline_noise(np.zeros(100), 100, step=0.04) == pytest.approx(0.04 / np.sqrt(12))


@pytest.mark.parametrize("amp_sigma", [13.0, 20.0, 40.0])
def test_a_pulse_well_above_the_noise_is_measured_and_its_snr_stated(amp_sigma):
    rep = analyze_record(record(amp_sigma), SETUP)
    assert rep.speed_m_per_s == pytest.approx(200.0, rel=0.02)
    for role in ("upper", "lower"):
        # SNR = the pulse's highest sample over the noise: the amplitude plus the largest noise
        # sample of the ~100 samples within one sigma of the top (2.5 sigma on average, under
        # 4.5 but for 1e-5 of records), and the noise estimate good to 6% (4000 samples)
        assert amp_sigma * 0.94 <= rep.snr[role] <= (amp_sigma + 4.5) * 1.06
    assert "speed_m_per_s" not in rep.reasons


@pytest.mark.parametrize("amp_sigma", [3.0, 6.0])
def test_a_pulse_below_the_snr_rule_is_refused_with_the_reason(amp_sigma):
    rep = analyze_record(record(amp_sigma), SETUP)
    assert rep.speed_m_per_s is None and rep.amplitude_N is None
    assert "baseline noise" in rep.reasons["speed_m_per_s"] and "10 x" in rep.reasons["speed_m_per_s"]


def test_a_blip_beside_a_large_signal_is_not_a_pulse():
    # the tester's TDS1012B pair: a 1.1 mV blip on one channel beside a noisy large signal
    rng = np.random.default_rng(5)
    big = 35.8 * np.sin(2 * np.pi * 1e3 * T) + rng.normal(0, 0.2, N)  # no quiet baseline
    blip = sech2(5e-4, 0.0011, 3e-6) + rng.normal(0, 0.0004, N)
    rec = ScopeRecord({"CH1": wave("CH1", blip), "CH2": wave("CH2", big)}, True)
    rep = analyze_record(rec, SETUP)
    assert rep.speed_m_per_s is None and "baseline noise" in rep.reasons["speed_m_per_s"]


def test_every_missing_figure_has_a_reason():
    for rep in (analyze_record(record(3.0), SETUP), analyze_record(ScopeRecord({}, False, "no edge"), SETUP)):
        d = rep.as_dict()
        assert all(d[f] is not None or f in d["reasons"] for f in FIGURES)
    rep = analyze_record(ScopeRecord({}, False, "no edge"), SETUP)
    assert "did not trigger: no edge" in rep.reasons["speed_m_per_s"]


def test_an_impossible_gauge_distance_gives_no_speed():
    far = replace(SETUP, lower=GaugeSetup("CH2", 19e3))  # "19 km": 88 million m/s
    rep = analyze_record(record(40.0), far)
    assert rep.speed_m_per_s is None and "outrun sound in the beads" in rep.reasons["speed_m_per_s"]
    steel = replace(SETUP, lower=GaugeSetup("CH2", 2.0), max_speed_m_per_s=4900.0)  # 9,300 m/s > bar speed
    assert "outrun" in analyze_record(record(40.0), steel).reasons["speed_m_per_s"]


def test_an_unresolved_time_of_flight_and_an_unphysical_width_are_refused():
    rep = analyze_record(record(1e4, delay=2 * H), replace(SETUP, max_speed_m_per_s=1e9))  # two samples apart
    assert rep.speed_m_per_s is None and "not resolved" in rep.reasons["speed_m_per_s"]
    wide = replace(SETUP, lower=GaugeSetup("CH2", 4.0))  # 18,500 m/s; with a bar speed of 20 km/s: 156 diameters
    rep = analyze_record(record(40.0), replace(wide, max_speed_m_per_s=2e4))
    assert rep.speed_m_per_s is None and "diameters wide" in rep.reasons["speed_m_per_s"]


def test_swapped_and_duplicated_channels_say_so():
    rec = record(40.0)
    swapped = replace(SETUP, upper=GaugeSetup("CH2", 0.0), lower=GaugeSetup("CH1", 0.0431))
    assert "channels swapped?" in analyze_record(rec, swapped).reasons["speed_m_per_s"]
    twice = ScopeRecord({"CH1": rec["CH1"], "CH2": rec["CH1"]}, True)
    assert "the same file twice?" in analyze_record(twice, SETUP).reasons["speed_m_per_s"]


def test_non_finite_samples_and_envelopes_are_refused_naming_the_channel():
    rec = record(40.0)
    nan = ScopeRecord({"CH1": rec["CH1"], "CH2": Waveform("CH2", replace(rec["CH2"].preamble, y_multiplier=np.nan),
                                                          codes=np.zeros(N, dtype=np.int8))}, True)
    assert "CH2 holds non-finite samples" in analyze_record(nan, SETUP).reasons["speed_m_per_s"]
    env = record(40.0, point_format="ENV")
    why = analyze_record(env, SETUP).reasons["speed_m_per_s"]
    assert "CH1 is an envelope (peak-detect) record" in why and "CH2 is an envelope" in why
