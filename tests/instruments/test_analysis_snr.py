"""The SNR rule: the noise from the pre-trigger baseline, a pulse must stand PeakRules.snr
noise levels above it, and the report states each channel's SNR."""
import math

import numpy as np
import pytest

from instruments.analysis import GaugeSetup, PeakRules, Setup, analyze_record, noise_level
from instruments.records import Preamble, ScopeRecord, Waveform

H = 1e-7
N, N_PRE = 30000, 5000
T = (np.arange(N) - N_PRE) * H  # s from the trigger
SIGMA = 0.01  # V


def sech2(t0, width=2e-5, amp=1.0):
    return amp / np.cosh((T - t0) / width) ** 2


def record(volts: dict, n_pre: int = N_PRE, fmt: str = "Y", triggered: bool = True) -> ScopeRecord:
    """Channels of volts (no codes, as a CSV file gives them)."""
    def pre(v):
        return Preamble(points=v.size, x_increment=H, x_zero=-n_pre * H, trigger_index=n_pre,
                                 y_multiplier=1.0, y_offset=0.0, y_zero=0.0, point_format=fmt)
    return ScopeRecord({ch: Waveform(ch, pre(v), samples=v) for ch, v in volts.items()}, triggered)


SETUP = Setup(GaugeSetup("CH1", 0.0), GaugeSetup("CH2", 0.04))  # 0.04 m in 200 us: 200 m/s


def pair(amp_up, amp_low, noise=None):
    """Two channels with leading pulses 200 us apart; noise: (rng, where) Gaussian noise of
    SIGMA on the whole record ("all") or on the pre-trigger part only ("pre")."""
    up, low = sech2(0.5e-3, amp=amp_up), sech2(0.7e-3, amp=amp_low)
    if noise is not None:
        rng, where = noise
        for v in (up, low):
            n = rng.normal(0.0, SIGMA, N)
            v += n if where == "all" else np.where(np.arange(N) < N_PRE, n, 0.0)
    return record({"CH1": up, "CH2": low})


def test_noise_of_gaussian_baseline_is_its_sigma():
    y = np.random.default_rng(1).normal(0.0, SIGMA, N)
    assert noise_level(y, N_PRE) == pytest.approx(SIGMA, rel=0.05)  # MAD of 5000 samples: ~2% scatter


def test_noise_ignores_a_spike_in_the_baseline():
    y = np.random.default_rng(2).normal(0.0, SIGMA, N)
    y[100:110] = 50 * SIGMA  # the standard deviation would read 2.2 sigma
    assert noise_level(y, N_PRE) == pytest.approx(SIGMA, rel=0.05)


def test_a_flat_8bit_baseline_has_the_quantisation_floor():
    assert noise_level(np.zeros(N), N_PRE, step=0.04) == pytest.approx(0.04 / math.sqrt(12))


def test_too_short_a_baseline_has_no_noise():
    assert noise_level(np.zeros(N), 15) is None


@pytest.mark.parametrize("factor,passes", [(1.05, True), (0.95, False)])
def test_a_pulse_just_above_the_threshold_passes_and_just_below_is_refused(factor, passes):
    rules = PeakRules()
    amp = factor * rules.snr * SIGMA
    rep = analyze_record(pair(amp, 10 * amp, (np.random.default_rng(3), "pre")), SETUP)
    snr = rep.snr["CH1"]
    assert snr == pytest.approx(factor * rules.snr, rel=0.05)  # the noise is SIGMA to 5%
    if passes:
        assert rep.speed_m_per_s == pytest.approx(200.0, rel=1e-3) and rep.reasons == {}
    else:
        assert rep.speed_m_per_s is None
        assert "CH1: no pulse stands 8 times above the pre-trigger noise" in rep.reasons["speed_m_per_s"]


@pytest.mark.parametrize("amp_sigmas,found", [(14.0, True), (4.0, False)])
def test_snr_rule_on_noise_everywhere(amp_sigmas, found):
    rep = analyze_record(pair(amp_sigmas * SIGMA, amp_sigmas * SIGMA, (np.random.default_rng(4), "all")), SETUP)
    assert (rep.speed_m_per_s is not None) == found
    if found:
        assert rep.speed_m_per_s == pytest.approx(200.0, rel=0.05)  # a noisy top moves each peak time by microseconds
        for ch in ("CH1", "CH2"):  # the noise on the pulse's top lifts its maximum by a sigma or two
            assert amp_sigmas - 0.5 < rep.snr[ch] < amp_sigmas + 3
    else:
        assert "no pulse stands 8 times above" in rep.reasons["amplitude_N"]
        assert rep.snr["CH1"] < 8 and rep.snr["CH2"] < 8


def test_a_blip_beside_a_large_signal_is_not_a_pulse():
    # the tester's TDS1012B pair: a millivolt blip on a quiet channel beside a 35.8 V one
    rng = np.random.default_rng(5)
    up = sech2(0.5e-3, amp=35.8) + rng.normal(0.0, 0.02, N)
    low = sech2(0.7e-3, amp=0.0011) + rng.normal(0.0, 0.0008, N)
    rep = analyze_record(record({"CH1": up, "CH2": low}), SETUP)
    assert rep.speed_m_per_s is None and rep.amplitude_N is None
    assert rep.reasons["speed_m_per_s"].startswith("CH2: no pulse stands 8 times above")
    assert rep.snr["CH1"] > 1000 and rep.snr["CH2"] < 8


def test_the_snr_threshold_is_a_rule_of_its_own():
    rep = analyze_record(pair(5 * SIGMA, 5 * SIGMA, (np.random.default_rng(3), "pre")),
                         Setup(SETUP.upper, SETUP.lower, rules=PeakRules(snr=4.0)))
    assert rep.speed_m_per_s == pytest.approx(200.0, rel=1e-3)
