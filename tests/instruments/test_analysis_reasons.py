"""No figure without a reason: each way the analysis cannot measure leaves its figures None
and says why; an implausible speed is not given."""
import numpy as np
import pytest
from test_analysis_snr import SETUP, N, record, sech2

from instruments.analysis import GaugeSetup, Setup, analyze_record
from instruments.analysis.plausibility import Limits
from instruments.analysis.report import FIGURES, SPEED_FIGURES
from instruments.errors import InstrumentError
from instruments.records import ScopeRecord


def clean_pair(t_up=0.5e-3, t_low=0.7e-3):
    return {"CH1": sech2(t_up), "CH2": sech2(t_low)}


def every_none_has_a_reason(rep):
    missing = {f for f in FIGURES if getattr(rep, f) is None}
    assert missing == set(rep.reasons), (missing, rep.reasons)


def refused(rep, text, figures=FIGURES):
    every_none_has_a_reason(rep)
    for f in figures:
        assert getattr(rep, f) is None and text in rep.reasons[f], (f, rep.reasons.get(f))


def test_a_clean_pair_gives_every_figure_and_no_reason():
    rep = analyze_record(record(clean_pair()), SETUP)
    assert rep.speed_m_per_s == pytest.approx(200.0, rel=1e-4)
    assert rep.reasons == {} and all(getattr(rep, f) is not None for f in FIGURES)
    assert rep.width_diameters == pytest.approx(1.763 * 2e-5 * 200.0 / 4.76e-3, rel=1e-3)  # FWHM of sech^2


def test_untriggered_record():
    refused(analyze_record(ScopeRecord({}, False, "no rising crossing of 0.05 V on CH1"), SETUP),
            "the scope did not trigger (no rising crossing of 0.05 V on CH1)")


def test_envelope_record():
    rec = record(clean_pair(), fmt="ENV")
    refused(analyze_record(rec, SETUP), "CH1: an envelope (peak-detect) record holds min/max pairs, not samples")


def test_non_finite_samples():
    v = clean_pair()
    v["CH2"][:] = np.nan  # a NaN scale factor makes every sample NaN
    refused(analyze_record(record(v), SETUP), "CH2: samples that are not finite numbers")


def test_the_same_record_twice():
    v = clean_pair()
    refused(analyze_record(record({"CH1": v["CH1"], "CH2": v["CH1"].copy()}), SETUP),
            "CH1 and CH2 hold the same record (the same file twice?)")


def test_swapped_channels():
    refused(analyze_record(record(clean_pair(0.7e-3, 0.5e-3)), SETUP), "channels swapped?")


def test_no_pulse_on_a_channel():
    v = clean_pair()
    v["CH2"] = np.random.default_rng(0).normal(0.0, 0.01, N)
    rep = analyze_record(record(v), SETUP)
    refused(rep, "CH2: no pulse stands 8 times above the pre-trigger noise")
    assert rep.snr["CH2"] < 8 and rep.snr["CH1"] > 1e3


def test_a_baseline_too_short_to_measure_the_noise():
    refused(analyze_record(record(clean_pair(), n_pre=4), SETUP), "fewer than 16 samples before the trigger")


def test_a_time_of_flight_of_two_samples():
    rep = analyze_record(record(clean_pair(0.5e-3, 0.5e-3 + 2e-7)), SETUP)
    refused(rep, "the time of flight is 2 samples", SPEED_FIGURES)
    assert rep.amplitude_N == pytest.approx(1.0, rel=1e-3)  # the pulses themselves were measured


def test_faster_than_the_bound():
    rep = analyze_record(record(clean_pair()), Setup(SETUP.upper, SETUP.lower, limits=Limits(max_speed_m_per_s=150.0)))
    refused(rep, "implausible speed: 200 m/s (40 mm in 200 us) is faster than 150 m/s", SPEED_FIGURES)


def test_a_gauge_distance_the_record_cannot_hold():
    rep = analyze_record(record(clean_pair()), Setup(SETUP.upper, GaugeSetup("CH2", 19e3)))
    refused(rep, "the record spans 0.003 s (is the gauge distance right?)", SPEED_FIGURES)


def test_a_pulse_too_wide_for_a_solitary_wave():
    narrow = Setup(SETUP.upper, SETUP.lower, limits=Limits(width_diameters=(0.5, 1.0)))
    rep = analyze_record(record(clean_pair()), narrow)
    refused(rep, "the leading pulse's FWHM is 1.48 bead diameters, outside the 0.5 to 1 of a solitary wave",
            SPEED_FIGURES)


def test_leading_pulse_only_says_the_train_was_not_counted():
    rep = analyze_record(record(clean_pair()), SETUP, train=False)
    assert rep.speed_m_per_s == pytest.approx(200.0, rel=1e-4)
    assert rep.reasons == {"pulses": "the train was not counted (leading pulse only)"}


@pytest.mark.parametrize("limits", [dict(max_speed_m_per_s=0.0), dict(min_flight_samples=-1.0),
                                    dict(width_diameters=(2.0, 1.0))])
def test_limits_refuse_nonsense(limits):
    with pytest.raises(InstrumentError, match="limits."):
        Limits(**limits)


def test_json_form_has_no_infinity():
    from instruments.analysis.report import Report

    d = Report(snr={"CH1": float("inf")}, noise={"CH1": 0.0}, duration_s=float("nan")).as_dict()
    assert d["snr"] == {"CH1": None} and d["noise"] == {"CH1": 0.0} and d["duration_s"] is None
