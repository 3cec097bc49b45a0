"""The batched instruments and analysis give each shot the bits it gets alone: the same
codes as PiezoGauge.read and Oscilloscope.acquire fed the same generator, the same Report
as the pipeline's analyze_record."""
import re

import numpy as np
import pytest

from instruments.analysis import GaugeSetup, PeakRules, Setup, analyze_record
from instruments.analysis.batch import analysed
from instruments.devices import batch
from instruments.devices.gauges import GaugeDraw, GaugeSettings, PiezoGauge
from instruments.devices.oscilloscope import AcquisitionStatus, ChannelSettings, Oscilloscope, Timebase, Trigger

H = 2e-7
N = 3000


def _pulse(t0, amp=5.0, width=40e-6):
    t = np.arange(N) * H
    return amp / np.cosh((t - t0) / width) ** 2


def _wiring(noise=1e-3, noise_floor=2e-4):
    gauges = ((ch, GaugeSettings(noise=noise), delayed)
              for ch, delayed in (("CH2", True), ("CH1", True), ("CH3", False)))
    channels = {c: ChannelSettings(volts_per_div=0.05, bandwidth=20e6) for c in ("CH1", "CH2", "CH3")}
    scope = Oscilloscope(channels=channels,
                         timebase=Timebase(2e-7, 2000), trigger=Trigger("CH1", 0.02, "rising", 0.3),
                         noise_floor=noise_floor)
    return batch.Wiring(tuple(gauges), scope)


def _alone(forces, wiring, seed, fixed, speed):
    """One shot the way Rig.fire reads it: each gauge's draw and read, then the scope."""
    rng = np.random.default_rng(seed)
    inputs = {}
    for k, (ch, settings, delayed) in enumerate(wiring.gauges):
        draw = GaugeDraw.draw(settings, rng)
        gain = draw.gain if np.isnan(fixed[k, 0]) else fixed[k, 0]
        mis = draw.misalignment if np.isnan(fixed[k, 1]) else fixed[k, 1]
        inputs[ch] = PiezoGauge(settings).read(forces[k], H, GaugeDraw(gain, mis), rng, speed if delayed else None)
    return wiring.scope.acquire(inputs, H, rng, {ch: settings.noise for ch, settings, _ in wiring.gauges})


@pytest.mark.parametrize("noise,noise_floor", [(1e-3, 2e-4), (0.0, 0.0)])
def test_a_batch_of_shots_reads_as_its_shots_alone(noise, noise_floor):
    wiring = _wiring(noise, noise_floor)
    S = 6
    # shots 3 and 4 trigger 60 us after the impact, within the 120 us pre-trigger: their
    # records start before the input, where the gauges are at rest
    early = np.array([0, 0, 0, 1, 1, 0]) * 1.4e-4
    forces = np.stack([np.stack([_pulse(2.0e-4 + 1e-6 * s - early[s]), _pulse(1.8e-4 + 1e-6 * s - early[s]),
                                 _pulse(4e-4, 9.0)]) for s in range(S)])
    seeds = [11 + 7 * s for s in range(S)]
    fixed = np.full((S, 3, 2), np.nan)
    fixed[1, 0, 0] = 1.07  # a study's own gain for one gauge of one shot
    speeds = np.full(S, 230.0)
    speeds[2] = np.nan  # no wave speed: no delay
    records = batch.acquire(forces, H, wiring, seeds, fixed, speeds)
    for s in range(S):
        alone = _alone(forces[s], wiring, seeds[s], fixed[s], None if np.isnan(speeds[s]) else speeds[s])
        together = records.record(s)
        assert together.triggered and alone.triggered
        assert together.trigger_time == alone.trigger_time
        for ch, w in alone.waveforms.items():
            assert np.array_equal(together.waveforms[ch].codes, w.codes), (s, ch)
            assert together.waveforms[ch].preamble == w.preamble
    setup = Setup(GaugeSetup("CH2", 0.0, 0.05, 1e-3), GaugeSetup("CH1", 0.0043, 0.05, 1e-3),
                  GaugeSetup("CH3", 0.02, 0.05, 1e-3), 4.76e-3, 1.1, 2.4, PeakRules())
    for s, rep in enumerate(analysed(records, setup)):
        ref = analyze_record(records.record(s), setup, train=False)
        assert rep.as_dict() == ref.as_dict(), s


@pytest.mark.parametrize("read", [("CH1", "CH2"), ("CH2",), ("CH2", "CH3"), ("CH1", "CH3")])
def test_channels_nobody_reads_are_skipped_without_changing_the_others(read):
    # a study reads two channels: the others are neither filtered nor converted and the
    # last one's scope noise is not drawn, yet the channels read keep their bits, records
    # that start before the impact (shots 1 and 2) included; the trigger's source (CH1)
    # is always read
    wiring = _wiring()
    early = np.array([0, 1, 1, 0]) * 1.4e-4
    forces = np.stack([np.stack([_pulse(2.0e-4 - early[s]), _pulse(1.8e-4 + 1e-6 * s - early[s]),
                                 _pulse(4e-4, 9.0)]) for s in range(4)])
    seeds, speeds = [3, 5, 8, 13], np.full(4, 230.0)
    whole = batch.acquire(forces, H, wiring, seeds, None, speeds)
    part = batch.acquire(forces, H, wiring, seeds, None, speeds, read=read)
    kept = sorted(set(read) | {"CH1"})
    assert [ch for ch, r in zip(wiring.channels, part.read) if r] == kept
    assert np.array_equal(part.times, whole.times) and np.array_equal(part.status, whole.status)
    for s in range(4):
        rec, ref = part.record(s), whole.record(s)
        assert sorted(rec.waveforms) == kept
        for ch in kept:
            assert np.array_equal(rec.waveforms[ch].codes, ref.waveforms[ch].codes), (s, ch)
    setup = Setup(GaugeSetup("CH2", 0.0, 0.05, 1e-3), GaugeSetup("CH1", 0.0043, 0.05, 1e-3))
    if {"CH1", "CH2"} <= set(kept):
        assert [r.as_dict() for r in analysed(part, setup)] == [r.as_dict() for r in analysed(whole, setup)]


def test_before_the_impact_a_record_reads_the_gauges_at_rest():
    """A pre-trigger longer than the time from the impact to the trigger: the record's
    samples before the impact carry the gauges' noise about their rest level (0 V), not a
    held first sample; the trigger's time is counted from the impact."""
    wiring = _wiring(noise=4e-3, noise_floor=0.0)  # 2 codes rms: the spread is read off the codes
    forces = np.stack([_pulse(9e-5, width=20e-6), _pulse(8e-5, width=20e-6), _pulse(4e-4, 9.0)])[None]  # CH2, CH1
    records = batch.acquire(forces, H, wiring, [5])
    rec = records.record(0)
    t_first = rec.trigger_time + rec.waveforms["CH1"].preamble.x_zero
    assert 0 < rec.trigger_time < 70e-6  # the trigger on CH1's rise, the pre-trigger 120 us
    assert t_first == pytest.approx(rec.trigger_time - 120e-6, abs=2e-7)
    w = rec.waveforms["CH3"]  # the wall sensor: quiet for 150 us after the impact too
    t = w.time() + rec.trigger_time  # from the impact
    before, after = w.volts()[t < 0], w.volts()[(t > 0) & (t < 100e-6)]
    assert before.size > 300 and after.size > 300
    # the same noise before the impact as after it: sds agree within 15% (an sd of ~400
    # samples is good to 1/sqrt(2 x 400) = 3.5%), the mean is 0 V within 4 standard errors
    assert before.std() == pytest.approx(after.std(), rel=0.15)
    assert after.std() > 1e-3  # the gauge's 4 mV through the bandwidth limit, rounded to 2 mV codes
    assert abs(before.mean()) < 4 * before.std() / np.sqrt(before.size)


def test_a_shot_that_does_not_trigger_or_outlasts_its_input_says_so():
    wiring = _wiring()
    forces = np.stack([np.stack([_pulse(2e-4, 1e-4), _pulse(1.8e-4, 1e-4), _pulse(4e-4)]),  # far below the level
                       np.stack([_pulse(5.9e-4), _pulse(5.8e-4), _pulse(5.9e-4)])])  # triggers too late
    records = batch.acquire(forces, H, wiring, [1, 2])
    assert list(records.status) == [batch.NO_TRIGGER, batch.PAST_INPUT]
    assert not records.record(0).triggered
    setup = Setup(GaugeSetup("CH2"), GaugeSetup("CH1", 0.0043))
    assert "did not trigger" in analysed(records, setup)[0].reasons["speed_m_per_s"]
    # the compiled codes leave the batch as the scope's named status, with the reason the analysis gives
    assert [records.outcome(s) for s in (0, 1)] == [AcquisitionStatus.NO_TRIGGER, AcquisitionStatus.PAST_INPUT]
    assert all(type(records.outcome(s)) is AcquisitionStatus for s in (0, 1))
    reasons = [r.reasons["speed_m_per_s"] for r in analysed(records, setup)]
    assert [records.outcome(s).message in reasons[s] for s in (0, 1)] == [True, True]
    assert "runs past the input" in reasons[1]


def test_a_clipped_gauge_channel_gives_no_figure_alone_or_in_a_batch():
    # 9 N at 0.05 V/N is 0.45 V, off a 50 mV/div screen: the pulse's top is cut, so its
    # amplitude, width and time are not measured; the batch and the lone record agree
    wiring = _wiring()
    forces = np.stack([np.stack([_pulse(1.8e-4, 9.0), _pulse(2.0e-4, 3.0), _pulse(4e-4, 3.0)]),
                       np.stack([_pulse(1.8e-4, 3.0), _pulse(2.0e-4, 3.0), _pulse(4e-4, 3.0)])])
    records = batch.acquire(forces, H, wiring, [1, 2])
    assert records.over[0].tolist() == [False, True, False] and not records.over[1].any()
    setup = Setup(GaugeSetup("CH2", 0.0, 0.05, 1e-3), GaugeSetup("CH1", 0.0043, 0.05, 1e-3))
    reports = analysed(records, setup)
    alone = analyze_record(records.record(0), setup, train=False)
    assert reports[0].as_dict() == alone.as_dict()
    assert alone.speed_m_per_s is None and alone.amplitude_N is None
    assert re.match(r"CH2: clipped: \d+ samples at the ADC's top, a flat top of \d+ samples .*: the signal ran off "
                    r"the scope's range", alone.reasons["amplitude_N"])
    assert reports[1].speed_m_per_s is not None and set(reports[1].reasons) == {"pulses"}  # leading pulse only


@pytest.mark.parametrize("bandwidth", [20e6, 20e3])
def test_the_figures_of_a_batch_are_its_reports_figures_whatever_refuses_them(bandwidth):
    # a study takes a batch's figures as arrays, judged by the rules over the whole batch
    # (verdicts.py), with no Report built: for shots that every rule refuses in turn they
    # are the figures of the Reports analysed words, which are the lone records' Reports
    from instruments.analysis.batch import analysed_figures

    wiring = _wiring()
    channels = {c: ChannelSettings(volts_per_div=0.05, bandwidth=bandwidth) for c in ("CH1", "CH2", "CH3")}
    wiring = batch.Wiring(wiring.gauges, Oscilloscope(channels=channels, timebase=wiring.scope.timebase,
                                                      trigger=wiring.scope.trigger, noise_floor=2e-4))
    pairs = [(1.0e-4, 1.6e-4, 3.0, 3.0),  # measured
             (1.6e-4, 1.0e-4, 3.0, 3.0),  # the lower pulse first
             (1.0e-4, 1.005e-4, 3.0, 3.0),  # 2.5 samples of flight
             (1.0e-4, 1.6e-4, 0.0, 3.0),  # no upper pulse
             (1.0e-4, 1.6e-4, 5.12, 3.0),  # at the rail for a few samples: the speed stands it, the amplitude not
             (1.0e-4, 1.6e-4, 6.0, 3.0),  # at the rail for 40 samples: no figure
             (1.0e-4, 1.6e-4, 3.0, 1e-4),  # no trigger
             (5.9e-4, 5.8e-4, 3.0, 3.0)]  # the record runs past the input
    forces = np.stack([np.stack([_pulse(a, amp_a, 10e-6), _pulse(b, amp_b, 10e-6), _pulse(4e-4, 3.0)])
                       for a, b, amp_a, amp_b in pairs])
    fixed = np.full((len(pairs), 3, 2), np.nan)
    fixed[:, :, 0] = 1.0  # no gain drawn: the rail cuts the tops the cases say
    records = batch.acquire(forces, H, wiring, list(range(1, len(pairs) + 1)), fixed)
    setup = Setup(GaugeSetup("CH2", 0.0, 0.05, 1e-3), GaugeSetup("CH1", 0.0043, 0.05, 1e-3), None, 1e-3)
    figures = analysed_figures(records, setup)
    reports = analysed(records, setup)
    for s, rep in enumerate(reports):
        if records.outcome(s) is AcquisitionStatus.OK:
            assert rep.as_dict() == analyze_record(records.record(s), setup, train=False).as_dict(), s
        for name, x in figures.items():
            want = getattr(rep, name)
            assert (np.isnan(x[s]) if want is None else x[s] == want), (s, name)
    if bandwidth < 1e6:  # the channel's rise time 0.35/B = 17.5 us, over a third of the pulses' 17.6 us FWHM
        assert all("bandwidth limit" in r.reasons["speed_m_per_s"] for r in (reports[0], reports[2]))
    else:
        assert reports[0].speed_m_per_s is not None and reports[0].amplitude_N is not None
        assert "comes before or with" in reports[1].reasons["speed_m_per_s"]
        assert f"under the {setup.limits.min_flight_samples:g}" in reports[2].reasons["speed_m_per_s"]
        assert reports[2].amplitude_N is not None  # an implausible speed keeps the amplitudes
        assert "CH2: no pulse" in reports[3].reasons["speed_m_per_s"]
        assert reports[4].speed_m_per_s is not None and "ran off the scope's range" in reports[4].reasons["amplitude_N"]
        assert reports[5].speed_m_per_s is None and "ran off the scope's range" in reports[5].reasons["speed_m_per_s"]
    assert "did not trigger" in reports[6].reasons["speed_m_per_s"]
    assert "runs past the input" in reports[7].reasons["speed_m_per_s"]


def test_auto_mode_in_a_batch_gives_each_shot_its_bits_alone():
    """AUTO: a shot that does not trigger is taken untriggered at the impact (its record
    starts before the input, read at rest), one that triggers as in NORMal; in a batch each
    has the bits it has alone, and the analysis refuses the untriggered one with its reason."""
    wiring = _wiring()
    wiring = batch.Wiring(wiring.gauges, Oscilloscope(
        channels=wiring.scope.channels, timebase=wiring.scope.timebase,
        trigger=Trigger("CH1", 0.02, "rising", 0.3, "auto"), noise_floor=wiring.scope.noise_floor))
    forces = np.stack([np.stack([_pulse(2e-4, 1e-4), _pulse(1.8e-4, 1e-4), _pulse(4e-4)]),  # far below the level
                       np.stack([_pulse(2.0e-4), _pulse(1.8e-4), _pulse(4e-4, 9.0)])])
    seeds, speeds = [1, 2], np.full(2, 230.0)
    records = batch.acquire(forces, H, wiring, seeds, None, speeds)
    assert [records.outcome(s) for s in (0, 1)] == [AcquisitionStatus.AUTO, AcquisitionStatus.OK]
    for s in range(2):
        alone = _alone(forces[s], wiring, seeds[s], np.full((3, 2), np.nan), speeds[s])
        together = records.record(s)
        assert together.triggered == alone.triggered == (s == 1)
        assert together.trigger_time == alone.trigger_time == (0.0 if s == 0 else together.trigger_time)
        for ch, w in alone.waveforms.items():
            assert np.array_equal(together.waveforms[ch].codes, w.codes), (s, ch)
            assert together.waveforms[ch].preamble == w.preamble
    assert records.record(0)["CH1"].preamble.x_zero < -1e-4  # 30% of 400 us before the impact
    setup = Setup(GaugeSetup("CH2"), GaugeSetup("CH1", 0.0043))
    assert AcquisitionStatus.AUTO.message in analysed(records, setup)[0].reasons["speed_m_per_s"]
