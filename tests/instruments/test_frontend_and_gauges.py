"""Each emulated analog effect against its analytic response (no rig import here)."""
import math

import numpy as np
import pytest

from instruments.devices.frontend import lowpass, rc_highpass
from instruments.devices.gauges import GaugeDraw, GaugeSettings, PiezoGauge

H = 1e-7


def test_rc_droop_and_undershoot_match_the_one_pole_response():
    # a 1 N rectangular load of width T through a tau = 1 ms high-pass: y = g exp(-t/tau)
    # during the load, then g (exp(-T/tau) - 1) exp(-(t-T)/tau) after it, where
    # g = (tau/h)(1 - exp(-h/tau)) is the exact response to the one-sample ramp that a
    # sampled step is (first-order hold); g -> 1 as h/tau -> 0
    tau, T = 1e-3, 0.4e-3
    g = tau / H * (1 - math.exp(-H / tau))
    n = np.arange(20000)
    start, width = 1000, int(round(T / H))
    x = np.where((n >= start) & (n < start + width), 1.0, 0.0)
    y = rc_highpass(x, H, tau)
    s = (n - start) * H
    during = (n >= start) & (n < start + width)
    after = n >= start + width
    assert np.allclose(y[during], g * np.exp(-s[during] / tau), rtol=0, atol=1e-12)
    undershoot = g * (math.exp(-T / tau) - 1)
    assert np.allclose(y[after], undershoot * np.exp(-(s[after] - T) / tau), rtol=0, atol=1e-12)
    assert y[after].min() == pytest.approx(undershoot, abs=1e-12)


def test_constant_load_reads_zero():
    assert np.all(rc_highpass(np.full(1000, 2.38), H, 1e-3) == 0.0)


def test_bandwidth_limit_rise_time_is_0p35_over_bw():
    bw, h = 20e6, 1e-10
    x = np.r_[np.zeros(100), np.ones(20000)]
    y = lowpass(x, h, bw)
    t10 = np.argmax(y >= 0.1) * h
    t90 = np.argmax(y >= 0.9) * h
    assert t90 - t10 == pytest.approx(0.35 / bw, rel=0.01)


def test_gauge_noise_rms_is_as_set():
    g = PiezoGauge(GaugeSettings(noise=2e-3))
    v = g.read(np.zeros(100_000), H, GaugeDraw(1.0, 0.0), np.random.default_rng(3))
    assert np.std(v) == pytest.approx(2e-3, rel=0.02)  # 100,000 samples: sd of the estimate 0.2%


def test_misalignment_shifts_arrival_by_distance_over_speed():
    t = np.arange(4000) * H
    pulse = np.exp(-(((t - 2e-4) / 2e-5) ** 2))
    g = PiezoGauge(GaugeSettings(noise=0.0, tau=1.0))
    rng = np.random.default_rng(0)
    nominal = g.read(pulse, H, GaugeDraw(1.0, 0.0), rng, wave_speed=200.0)
    shifted = g.read(pulse, H, GaugeDraw(1.0, 1e-3), rng, wave_speed=200.0)
    delay = (np.argmax(shifted) - np.argmax(nominal)) * H
    assert delay == pytest.approx(1e-3 / 200.0, abs=H)


def test_calibration_gain_scales_the_signal():
    g = PiezoGauge(GaugeSettings(sensitivity=0.05, noise=0.0, tau=1.0))
    v = g.read(np.r_[0.0, np.full(99, 10.0)], H, GaugeDraw(1.1, 0.0), np.random.default_rng(0))
    assert v[1] == pytest.approx(0.05 * 1.1 * 10.0, rel=1e-6)
