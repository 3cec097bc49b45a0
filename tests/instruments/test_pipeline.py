"""Analysis and pipeline on signals whose answers are known; no rig import anywhere here."""
import subprocess
import sys

import numpy as np
import pytest

from instruments.analysis import (
    GaugeSetup,
    PeakRules,
    Setup,
    analyze_forces,
    analyze_record,
    find_pulses,
    invert_rc,
    leading,
    xcorr_delay,
)
from instruments.devices.frontend import rc_highpass
from instruments.devices.oscilloscope import ChannelSettings, Oscilloscope, Timebase, Trigger

H = 1e-7
T = np.arange(30000) * H


def sech2(t0, width, amp=1.0):
    return amp / np.cosh((T - t0) / width) ** 2


def test_pipeline_modules_do_not_import_the_simulator():
    code = ("import sys, instruments.analysis.pipeline, instruments.archive, instruments.formats; "
            "print(any(m == 'rig' or m.startswith('rig.') for m in sys.modules))")
    assert subprocess.run([sys.executable, "-c", code], capture_output=True, text=True).stdout.strip() == "False"


def test_pulse_time_amplitude_and_widths_of_a_sech2():
    w = 2e-5
    (p,) = find_pulses(T, sech2(1.23456e-3, w, 3.0))
    assert p.time == pytest.approx(1.23456e-3, abs=1e-9)
    # the parabola through the top 5% reads a sech^2 peak low by about 1.4e-4 (its x^4 term)
    assert p.amplitude == pytest.approx(3.0, rel=5e-4)
    # the half level inherits the amplitude's 1.4e-4: FWHM to 3e-4
    assert p.fwhm == pytest.approx(2 * w * np.arccosh(np.sqrt(2)), rel=3e-4)  # sech^2 = 1/2
    assert p.base_width == pytest.approx(2 * w * np.arccosh(10.0), rel=1e-3)  # sech^2 = 1/100


def test_parabola_fit_survives_8bit_plateaus():
    # quantised to 1/100 of the amplitude, the top is a plateau of equal values
    f = np.round(sech2(1.0e-3 + 0.037e-6, 1e-5) * 100) / 100
    (p,) = find_pulses(T, f)
    assert abs(p.time - (1.0e-3 + 0.037e-6)) < 0.05e-6  # far below the 2 us plateau


def test_rc_inversion_recovers_the_pulse():
    f = sech2(1e-3, 5e-5)
    y = rc_highpass(f, H, 1e-3)
    assert y.max() < 0.96  # the droop is real: (1/tau) * integral of f up to the peak = 5%
    assert np.max(np.abs(invert_rc(y, H, 1e-3) - f)) < 1e-6


def test_time_of_flight_two_ways_and_train_count():
    a, b = sech2(0.5e-3, 2e-5), sech2(0.7e-3, 2e-5)  # 200 us apart
    train = b + sech2(0.85e-3, 2e-5, 0.5) + sech2(1.0e-3, 2e-5, 0.2) + sech2(1.1e-3, 2e-5, 0.02)
    pa, pb = find_pulses(T, a)[0], find_pulses(T, train)[0]
    assert xcorr_delay(T, a, pa, train, pb) == pytest.approx(200e-6, abs=2e-8)
    setup = Setup(GaugeSetup("A", 0.0), GaugeSetup("B", 0.05))
    rep = analyze_forces(T, {"upper": a, "lower": train}, setup)
    assert rep.speed_m_per_s == pytest.approx(0.05 / 200e-6, rel=1e-4)
    assert rep.speed_xcorr_m_per_s == pytest.approx(0.05 / 200e-6, rel=1e-3)
    assert rep.pulses == 3  # the 2% one is below 5% of the leading pulse


def test_the_delay_of_a_finely_sampled_pair_is_the_full_correlations_at_a_bounded_cost():
    """0.2 ns samples (a 200 ns/div record): the leading pulse's window holds 0.35 M samples,
    searched every 85th sample first, then at every sample near that peak: the delay to a
    sample's fraction (the coarse search alone would be off by up to 85/2 samples, 8 ns);
    a window just past XCORR_POINTS (every 2nd sample first) gives the full correlation's
    peak and parabola, computed here with numpy."""
    from instruments.analysis._kernels.correlation import XCORR_POINTS

    h = 2e-10
    t = np.arange(int(0.32e-3 / h)) * h
    a = 1.0 / np.cosh((t - 0.05e-3) / 2e-5) ** 2
    b = 1.0 / np.cosh((t - (0.25e-3 + 0.37 * h)) / 2e-5) ** 2
    pa, pb = find_pulses(t, a)[0], find_pulses(t, b)[0]
    assert xcorr_delay(t, a, pa, b, pb) == pytest.approx(0.2e-3 + 0.37 * h, abs=0.05 * h)
    h = 2 * pa.fwhm / (XCORR_POINTS * 2.5)  # a window of 2.5 XCORR_POINTS samples: searched every 2nd first
    t = np.arange(int(0.32e-3 / h)) * h
    a = 1.0 / np.cosh((t - 0.05e-3) / 2e-5) ** 2
    b = 0.7 / np.cosh((t - 0.25e-3) / 2.2e-5) ** 2  # wider and lower: a correlation peak of its own shape
    pa, pb = find_pulses(t, a)[0], find_pulses(t, b)[0]
    ia0, ia1 = np.searchsorted(t, [pa.time - pa.fwhm, pa.time + pa.fwhm])  # a's window, b's twice as wide
    ib0, ib1 = np.searchsorted(t, [pb.time - 2 * pa.fwhm, pb.time + 2 * pa.fwhm])
    c = np.correlate(b[ib0:ib1], a[ia0:ia1], mode="valid")
    k = int(np.argmax(c))
    full = (ib0 + k + 0.5 * (c[k - 1] - c[k + 1]) / (c[k - 1] - 2 * c[k] + c[k + 1]) - ia0) * h
    assert xcorr_delay(t, a, pa, b, pb) == pytest.approx(full, abs=1e-6 * h)


def test_a_quantised_train_counts_each_flat_top_once():
    # 8-bit-like codes with a flicker of one code: each flat top holds several local maxima
    # at the top code, each with the whole pulse as its prominence (scipy's ties); they are
    # one pulse, not a train of their own
    rng = np.random.default_rng(4)
    a = sech2(0.5e-3, 2e-5)
    train = sech2(0.7e-3, 2e-5) + sech2(0.85e-3, 2e-5, 0.5) + sech2(1.0e-3, 2e-5, 0.2)
    def flicker(f):
        return np.round(f * 40 + rng.uniform(-0.3, 0.3, f.size)) / 40
    quantised = flicker(train)
    assert len(find_pulses(T, quantised, floor=0.05)) > 3  # what the maxima alone say
    setup = Setup(GaugeSetup("A", 0.0), GaugeSetup("B", 0.05))
    rep = analyze_forces(T, {"upper": flicker(a), "lower": quantised}, setup)
    assert rep.pulses == 3


def test_leading_pulse_is_the_first_large_one_even_when_a_reflection_is_larger():
    f = sech2(1e-3, 2e-5, 1.0) + sech2(2e-3, 2e-5, 1.8) + sech2(0.5e-3, 2e-5, 0.05)
    assert leading(find_pulses(T, f), PeakRules()).time == pytest.approx(1e-3, abs=1e-9)


def test_full_pipeline_on_an_emulated_scope_record():
    tau, sens = 1e-3, 0.05
    up, low = sech2(1e-3, 3e-5, 4.0), sech2(1.2e-3, 3e-5, 4.0)
    scope = Oscilloscope(channels={"CH1": ChannelSettings(0.05, -1.0), "CH2": ChannelSettings(0.05, -1.0)},
                         timebase=Timebase(2e-7, 10000), trigger=Trigger("CH1", 0.03, "rising", 0.1),
                         noise_floor=0.0)
    volts = {"CH1": rc_highpass(sens * up, H, tau), "CH2": rc_highpass(sens * low, H, tau)}
    rec = scope.acquire(volts, H, np.random.default_rng(0))
    setup = Setup(GaugeSetup("CH1", 0.0, sens, tau), GaugeSetup("CH2", 0.04, sens, tau), beta=1.1,
                  static_force_N=2.4)
    rep = analyze_record(rec, setup)
    assert rep.speed_m_per_s == pytest.approx(200.0, rel=2e-3)
    assert rep.averaged_amplitude_N == pytest.approx(4.0, rel=1e-2)  # 8-bit: 1 code = 1% of this pulse
    assert rep.amplitude_N == pytest.approx(1.1 * rep.averaged_amplitude_N)
    assert rep.total_force_N == pytest.approx(rep.amplitude_N + 2.4)
    assert rep.reasons == {}
    # noise-free inputs: the noise is the 8-bit floor, one code (0.05 V/div / 25 codes per
    # division / 0.05 V/N = 0.04 N) / sqrt(12), and a 4 N pulse stands about 350 times above it
    assert rep.noise == {ch: pytest.approx(0.04 / 12 ** 0.5, rel=1e-6) for ch in ("CH1", "CH2")}
    assert rep.snr["CH1"] == pytest.approx(4.0 / (0.04 / 12 ** 0.5), rel=0.02)
