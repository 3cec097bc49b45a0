"""The emulated Tektronix scope: quantisation, clipping, trigger, noise, no-trigger."""
import numpy as np
import pytest

from instruments.devices.oscilloscope import ChannelSettings, Oscilloscope, Timebase, Trigger, per_division
from instruments.errors import InstrumentError

H = 1e-7


def _pulse(n=30000, at=1e-3, width=5e-5, amp=0.2):
    t = np.arange(n) * H
    return amp * np.exp(-(((t - at) / width) ** 2))


def _scope(**kw):
    ch = kw.pop("channels", {"CH1": ChannelSettings(volts_per_div=0.05, bandwidth=None)})
    return Oscilloscope(channels=ch, timebase=kw.pop("timebase", Timebase(2e-7, 5000)),
                        trigger=kw.pop("trigger", Trigger("CH1", 0.05, "rising", 0.2)), **kw)


def test_quantisation_step_is_v_per_div_over_25():
    rec = _scope(noise_floor=0.0).acquire({"CH1": _pulse()}, H, np.random.default_rng(1))
    w = rec["CH1"]
    assert w.preamble.y_multiplier == 0.05 / 25
    v = w.volts()
    steps = np.unique(np.round(np.diff(np.unique(v)) / w.preamble.y_multiplier, 9))
    assert steps.min() == 1.0  # every level is a whole number of 2 mV codes
    assert w.codes.dtype == np.int8


def test_clipping_sets_the_over_range_flag():
    small = _scope(noise_floor=0.0).acquire({"CH1": _pulse(amp=0.2)}, H, np.random.default_rng(1))
    big = _scope(noise_floor=0.0).acquire({"CH1": _pulse(amp=0.5)}, H, np.random.default_rng(1))
    assert not small["CH1"].overrange
    assert big["CH1"].overrange and big["CH1"].codes.max() == 127


@pytest.mark.parametrize("seed", range(5))
def test_trigger_lands_within_one_sample_of_the_crossing(seed):
    x = _pulse()
    rec = _scope(noise_floor=0.0).acquire({"CH1": x}, H, np.random.default_rng(seed))
    w = rec["CH1"]
    t = np.arange(x.size) * H
    i = np.argmax(x >= 0.05)
    t_cross = t[i - 1] + (0.05 - x[i - 1]) / (x[i] - x[i - 1]) * H
    assert abs(rec.trigger_time - t_cross) < 1e-12
    k = w.preamble.trigger_index
    assert k == 1000  # 20% of 5000 points before the trigger
    sample_t = rec.trigger_time + w.time()
    assert sample_t[k - 1] < t_cross <= sample_t[k]
    assert 0 <= sample_t[k] - t_cross < w.preamble.x_increment


def test_unconnected_channel_reads_the_noise_floor():
    chans = {"CH1": ChannelSettings(volts_per_div=0.05), "CH4": ChannelSettings(volts_per_div=1e-3)}
    rec = _scope(channels=chans, noise_floor=2e-4).acquire({"CH1": _pulse()}, H, np.random.default_rng(2))
    assert np.std(rec["CH4"].volts()) == pytest.approx(2e-4, rel=0.05)  # 5000 samples, 0.04 mV steps


def test_averaging_reduces_the_scope_noise():
    chans = {"CH1": ChannelSettings(volts_per_div=0.05), "CH4": ChannelSettings(volts_per_div=1e-3)}
    rec = _scope(channels=chans, noise_floor=4e-4, mode="average", averages=16).acquire(
        {"CH1": _pulse()}, H, np.random.default_rng(2))
    assert np.std(rec["CH4"].volts()) == pytest.approx(1e-4, rel=0.06)


def test_no_trigger_is_an_outcome_not_an_exception():
    rec = _scope().acquire({"CH1": _pulse(amp=0.01)}, H, np.random.default_rng(0))
    assert not rec.triggered and rec.waveforms == {} and "no rising crossing" in rec.reason


def test_same_seed_same_bits():
    a = _scope().acquire({"CH1": _pulse()}, H, np.random.default_rng(7))["CH1"]
    b = _scope().acquire({"CH1": _pulse()}, H, np.random.default_rng(7))["CH1"]
    assert np.array_equal(a.codes, b.codes) and a.preamble == b.preamble


@pytest.mark.parametrize("make,field", [
    (lambda: ChannelSettings(volts_per_div=0), "volts_per_div"),
    (lambda: ChannelSettings(volts_per_div=-0.1), "volts_per_div"),
    (lambda: ChannelSettings(coupling="XY"), "coupling"),
    (lambda: Timebase(1e-7, 0), "record_length"),
    (lambda: Trigger(slope="up"), "slope"),
    (lambda: _scope(trigger=Trigger("CH2")), "trigger.source"),
])
def test_bad_settings_name_the_field(make, field):
    with pytest.raises(InstrumentError, match=field):
        make()


def test_the_wfid_prints_v_per_div_and_s_per_div_as_a_scope_does():
    """'50.00mV/div, 250.0us/div', as a DPO/MSO's WFID (and the exports that carry it)
    prints them, not '0.05V/div, 0.00025s/div'."""
    assert [per_division(0.05, "V"), per_division(2.5e-4, "s"), per_division(1.0, "V"), per_division(0.2, "V", 3)] \
        == ["50.00mV", "250.0us", "1.000V", "200mV"]
    scope = Oscilloscope(channels={"CH1": ChannelSettings(0.05, 0.0)}, timebase=Timebase(2.5e-7, 10000),
                         trigger=Trigger("CH1", 0.01, "rising", 0.1))
    t = np.arange(20000) * 2.5e-7
    rec = scope.acquire({"CH1": 0.1 * np.exp(-(((t - 2e-3) / 1e-4) ** 2))}, 2.5e-7, np.random.default_rng(0))
    assert "50.00mV/div, 250.0us/div, 10000 points" in rec["CH1"].preamble.waveform_id


@pytest.mark.parametrize("slope", ["rising", "falling"])
def test_an_edge_trigger_has_a_noise_band_and_fires_on_its_own_flank(slope):
    """A pulse of 0.2 V whose flanks carry a +-3 mV ripple (1.5 codes at 50 mV/div) through
    the 0.1 V level: the ripple crosses the level downwards on the rising flank too, where a
    falling trigger without hysteresis had fired. With the band (0.2 div) each slope fires
    on its own flank, at the crossing of the level the comparator's turn belongs to."""
    h = 1e-7
    t = np.arange(40000) * h
    pulse = 0.2 * np.exp(-0.5 * ((t - 2e-3) / 2e-4) ** 2)
    x = pulse + 0.003 * np.sin(2 * np.pi * np.arange(t.size) / 4.0)
    rise, fall = 2e-3 - 2e-4 * np.sqrt(2 * np.log(2)), 2e-3 + 2e-4 * np.sqrt(2 * np.log(2))  # pulse = 0.1 V
    scope = Oscilloscope(channels={"CH1": ChannelSettings(0.05, 0.0)}, timebase=Timebase(1e-6, 2000),
                         trigger=Trigger("CH1", 0.1, slope, 0.5))
    rec = scope.acquire({"CH1": x}, h, np.random.default_rng(0))
    assert rec.triggered
    expected = rise if slope == "rising" else fall
    # the ripple moves a crossing by up to 3 mV over the flank's 590 V/s, 5 us; the other flank is 471 us away
    assert abs(rec.trigger_time - expected) < 10e-6, (rec.trigger_time, expected)


def _auto(mode="auto", pre=0.2):
    """A rising trigger at -0.4 V: an input resting at 0 V never crosses it (TRIGger:A:MODe's case)."""
    return _scope(noise_floor=0.0, trigger=Trigger("CH1", -0.4, "rising", pre, mode))


@pytest.mark.parametrize("pre,seed", [(0.2, 3), (0.0, 4)])
def test_auto_mode_takes_an_untriggered_record_whose_trigger_point_is_the_impact(pre, seed):
    """No crossing, AUTO: a record all the same, of the set length and interval, flagged
    untriggered; its samples are the input at t = x_zero + n dt from the impact (at rest,
    its first value, before it), each within one code; the clock's phase is drawn as for a
    triggered record, so the trigger point lies within one sample of the impact."""
    x = _pulse(at=3e-4)
    rec = _auto(pre=pre).acquire({"CH1": x}, H, np.random.default_rng(seed))
    w = rec["CH1"]
    assert not rec.triggered and rec.reason.startswith("auto-triggered: no rising crossing of -0.4 V")
    assert rec.trigger_time == 0.0 and w.preamble.extra["auto_triggered"] is True
    assert w.preamble.points == 5000 and w.preamble.x_increment == 2e-7
    assert w.preamble.trigger_index == round(pre * 5000)
    first_after = w.preamble.x_zero + w.preamble.trigger_index * 2e-7  # the first sample at or after t = 0
    assert 0.0 <= first_after < 2e-7
    t = w.time()
    expected = np.interp(t, np.arange(x.size) * H, x)  # np.interp holds x[0] before the input: its rest
    assert np.abs(w.volts() - expected).max() <= w.preamble.y_multiplier
    assert np.ptp(w.codes) > 50  # the pulse is in the record, not a flat line that matches anything


def test_normal_mode_gives_no_record_where_auto_gives_one_and_a_trigger_gives_the_same_record_in_both():
    x = _pulse(at=3e-4)
    normal = _auto("normal").acquire({"CH1": x}, H, np.random.default_rng(3))
    assert not normal.triggered and normal.waveforms == {} and normal.reason.startswith("no rising crossing")
    kw = {"noise_floor": 2e-4}
    a, n = (_scope(trigger=Trigger("CH1", 0.05, "rising", 0.2, mode), **kw).acquire(
        {"CH1": x}, H, np.random.default_rng(5)) for mode in ("auto", "normal"))
    assert a.triggered and n.triggered and a.trigger_time == n.trigger_time
    assert np.array_equal(a["CH1"].codes, n["CH1"].codes) and a["CH1"].preamble == n["CH1"].preamble


def test_the_trigger_mode_is_checked():
    with pytest.raises(InstrumentError, match="scope.trigger.mode = 'free': allowed normal, auto"):
        Trigger(mode="free")
