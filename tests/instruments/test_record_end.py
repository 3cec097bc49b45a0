"""A record that ends before the lower gauge's pulse does is named as such, with the time
it ends and what to change, not as a pulse that fails the peak rules."""
import numpy as np
import pytest

from instruments.analysis import GaugeSetup, Setup, analyze_record
from instruments.records import Preamble, ScopeRecord, Waveform

DT = 2e-7
N_PRE = 500
SETUP = Setup(GaugeSetup("CH1", 0.0, 0.05), GaugeSetup("CH2", 0.0427, 0.05))


def _record(n: int, lower_at_s: float, lower_peak_V: float = 0.2) -> ScopeRecord:
    """8-bit records of n samples (2 mV a code, a code of noise) of a 30 us pulse at 100 us
    (CH1) and one at ``lower_at_s`` (CH2), from the trigger."""
    rng = np.random.default_rng(3)
    t = DT * (np.arange(n) - N_PRE)
    waves = {}
    for ch, at, peak in (("CH1", 1e-4, 0.2), ("CH2", lower_at_s, lower_peak_V)):
        v = peak * np.exp(-0.5 * ((t - at) / 12e-6) ** 2)
        codes = np.clip(np.rint(v / 2e-3 + rng.normal(0, 1, n)), -128, 127).astype(np.int8)
        pre = Preamble(points=n, x_increment=DT, x_zero=-N_PRE * DT, trigger_index=N_PRE, y_multiplier=2e-3,
                       y_offset=0.0, y_zero=0.0)
        waves[ch] = Waveform(ch, pre, codes=codes)
    return ScopeRecord(waves, True)


@pytest.mark.parametrize("n", [1900, 1950])  # ends 10 us before and at the lower peak
def test_a_record_that_ends_in_the_lower_pulse_says_so(n):
    rep = analyze_record(_record(n, 2.9e-4), SETUP)
    end = DT * (n - 1 - N_PRE)
    assert rep.speed_m_per_s is None and rep.amplitude_N is None
    assert rep.reasons["speed_m_per_s"] == (f"CH2: the record ends during the pulse (at t = {end:.4g} s): a longer "
                                            f"record (scope.record_length) or a later trigger")


def test_a_record_that_ends_after_the_lower_peak_gives_the_speed_but_not_the_cut_cross_correlation():
    # 12 us (one standard deviation) after the peak: the peak time is in, the fall is not;
    # the cross-correlation of the cut pulse had given 245 m/s for 225 m/s
    rep = analyze_record(_record(2010, 2.9e-4), SETUP)
    assert rep.speed_m_per_s == pytest.approx(0.0427 / 1.9e-4, rel=0.01)
    assert rep.speed_xcorr_m_per_s is None and rep.pulses is None
    assert rep.reasons["speed_xcorr_m_per_s"].startswith("CH2: the record ends during the pulse (at t = 0.0003018 s), "
                                                         "before it falls to half its amplitude")


def test_the_whole_pulse_in_the_record_gives_the_speed_and_no_lower_pulse_is_not_a_cut_one():
    whole = analyze_record(_record(3000, 2.9e-4), SETUP)
    assert whole.speed_m_per_s == pytest.approx(0.0427 / 1.9e-4, rel=0.01)
    flat = analyze_record(_record(1950, 2.9e-4, lower_peak_V=0.0), SETUP)  # CH2 holds noise only
    why = flat.reasons["speed_m_per_s"]
    assert "record ends" not in why and "CH2: no pulse stands" in why
