"""The paper's elastic conversion of gauge readings (rig.theory.solitary.elastic_amplitude)
and measured points compared both ways (rig.fit.amplitudes), on constructed curves: no solve.

Construction: a reading r = F_d / beta(1 + F_d/F_0) converts back to F_d (the conversion is
the fixed point of F_d = beta(F_m/F_0) F_m,e, F_m = F_d + F_0). It stops when a step moves F_d
by less than 1e-10 of it, and each step is at most about a tenth of the last, so what is left
is about 1e-11 of F_d: 1e-8 leaves a margin of a thousand, and is far below any physical effect
(beta moves by 1e-3 between F_m/F_0 = 2 and 2.01).
"""
import math

import numpy as np
import pytest

from rig.errors import RigError
from rig.fit.amplitudes import both_conversions, elastic_curve
from rig.fit.data import Points
from rig.fit.evaluate import Curve
from rig.fit.points import PointObjective
from rig.theory.solitary import MIN_FORCE_RATIO, beta, elastic_amplitude

RTOL = 1e-8
GRAVITY, MAGNET = ("magnet.force=0.0",), ("magnet.force=2.38",)


def reading_of(F_d: float, F0: float) -> float:
    """The gauge reading that the paper's conversion turns into F_d on F_0."""
    return F_d / beta(1.0 + F_d / F0) if F0 > 0 else F_d / beta(math.inf)


@pytest.mark.parametrize("F_d,F0", [(3.0, 2.4), (2.0, 0.04), (1.5, 0.0)])
def test_a_reading_converts_back_to_the_force_it_was_made_from(F_d, F0):
    assert elastic_amplitude(reading_of(F_d, F0), F0) == pytest.approx(F_d, rel=RTOL)


def test_the_conversion_raises_a_reading_by_beta_between_1_and_the_sonic_vacuums():
    """beta >= 1 rises with F_m/F_0 to its sonic-vacuum value: a reading converts to more
    than itself, the more so on a smaller precompression."""
    r = 2.0
    low, high = elastic_amplitude(r, 2.4), elastic_amplitude(r, 0.04)
    assert r < low < high < beta(math.inf) * r


@pytest.mark.parametrize("reading,F0,match", [(0.0, 1.0, "reading"), (math.nan, 1.0, "reading"),
                                              (1.0, -1.0, "F0"), (0.02, 1.0, "below")])
def test_a_reading_outside_the_conversions_range_is_refused(reading, F0, match):
    assert MIN_FORCE_RATIO > 1.0 + 0.02 / 1.0  # the last case: F_m/F_0 below beta's range
    with pytest.raises(RigError, match=match):
        elastic_amplitude(reading, F0)


def _curve(F: np.ndarray, F0: float, a: float, s: float) -> Curve:
    """A curve V = a F^(1/6) over contact forces F whose readings convert to s F."""
    readings = np.array([reading_of(s * f, F0) for f in F])
    return Curve(np.linspace(0.3, 2.7, F.size), F, a * F ** (1 / 6), readings, np.full(F.size, F0))


def test_a_curves_readings_convert_shot_by_shot_and_a_curve_without_them_is_refused():
    F = np.array([0.5, 1.0, 2.0, 4.0])
    c = _curve(F, 0.03, 100.0, 1.2)
    c.reading[1] = math.nan
    c.reading[2] = 1e-6  # F_m/F_0 below beta's range: no point
    e = elastic_curve(c)
    assert e.force[[0, 3]] == pytest.approx(1.2 * F[[0, 3]], rel=RTOL)
    assert np.isnan(e.force[1]) and np.isnan(e.force[2]) and e.reading is None
    assert np.array_equal(e.speed, c.speed) and np.array_equal(e.velocity, c.velocity)
    with pytest.raises(RigError, match="no gauge readings"):
        elastic_curve(Curve(c.velocity, c.force, c.speed))


S = {GRAVITY: 1.1, MAGNET: 0.95}
A = {GRAVITY: 90.0, MAGNET: 160.0}
F0S = {GRAVITY: 0.03, MAGNET: 2.4}
CURVE_F = np.geomspace(1.0, 8.0, 5)
CONFIGS = (GRAVITY, GRAVITY, MAGNET, MAGNET, GRAVITY)
FORCE = np.array([2.0, 5.0, 3.0, 7.8, 7.5])
SPEED = np.array([105.0, 120.0, 190.0, 220.0, 125.0])


@pytest.fixture(scope="module")
def constructed():
    """(part, model, both_conversions): five points against curves V = a F^(1/6) of each
    configuration whose readings convert to s x their contact forces (one fitted parameter)."""
    pts = Points(FORCE, 0.2 * FORCE, SPEED, 0.1 * SPEED, CONFIGS, "constructed")
    part = PointObjective("ptfe52_gravity", (), pts)
    model = tuple(_curve(CURVE_F, F0S[c], A[c], S[c]) for c in part.configs)
    return part, model, both_conversions(part, model, 1)


def test_the_points_against_both_ways_on_constructed_curves(constructed):
    """Curves V = a F^(1/6) (straight in log-log, so the interpolation is exact), whose
    readings convert to s x their contact forces: at a point's F_d the contact way gives
    a F_d^(1/6), the elastic way a (F_d/s)^(1/6); residuals by the effective variance
    (dlnV/dlnF = 1/6); the contact way's are the fit's own; a point beyond the elastic
    curve's reach is measured from its end."""
    part, model, b = constructed
    s, a, F, configs, force, speed = S, A, CURVE_F, CONFIGS, FORCE, SPEED
    assert part.configs == [GRAVITY, MAGNET]
    fit_r = part.residuals(model, np.zeros(0))
    assert b["fit_uses"] == "contact_force" and b["dof"] == 4
    assert b["chi2_contact_force"] == pytest.approx(float(fit_r @ fit_r), rel=1e-12)
    for i, p in enumerate(b["points"]):
        c = configs[i]
        assert p["F_d_N"] == force[i] and p["V_s_m_per_s"] == speed[i] and p["configuration"] == list(c)
        V1 = a[c] * force[i] ** (1 / 6)
        assert p["model_V_s_contact_force_m_per_s"] == pytest.approx(V1, rel=1e-12)
        r1 = (V1 - speed[i]) / math.hypot(0.1 * speed[i], V1 / 6 / force[i] * 0.2 * force[i])
        assert p["residual_contact_force_sd"] == pytest.approx(r1, rel=1e-9)
        reach = force[i] <= s[c] * F[-1]
        assert p["reachable_elastic_conversion"] == reach
        if reach:
            V2 = a[c] * (force[i] / s[c]) ** (1 / 6)
            r2 = (V2 - speed[i]) / math.hypot(0.1 * speed[i], V2 / 6 / force[i] * 0.2 * force[i])
        else:  # beyond the elastic curve's end (s F_max, a F_max^(1/6)): its distance to the end
            F_e, V2 = s[c] * F[-1], a[c] * F[-1] ** (1 / 6)
            rv = (V2 - speed[i]) / math.hypot(0.1 * speed[i], V2 / 6 / F_e * 0.2 * force[i])
            r2 = math.copysign(math.hypot(rv, (force[i] - F_e) / (0.2 * force[i])), rv)
        assert p["model_V_s_elastic_conversion_m_per_s"] == pytest.approx(V2, rel=1e-8)
        assert p["residual_elastic_conversion_sd"] == pytest.approx(r2, rel=1e-7)
    point = b["points"][3]  # 7.8 N with the magnet: within the contact curve's 8 N, beyond the elastic one's 7.6 N
    assert point["reachable_contact_force"] and not point["reachable_elastic_conversion"]
    r2 = np.array([p["residual_elastic_conversion_sd"] for p in b["points"]])
    assert b["chi2_per_dof_elastic_conversion"] == pytest.approx(float(r2 @ r2) / 4, rel=1e-12)
    curve = b["curves"][1]
    assert curve["configuration"] == list(MAGNET) and curve["static_force_N"] == [2.4] * F.size
    assert curve["elastic_conversion_N"] == pytest.approx(list(0.95 * F), rel=RTOL)


def test_a_store_keeps_the_readings_and_one_without_them_reads_back_without(tmp_path):
    """The fit's store (an .npz of PointObjective.pack) keeps each curve's readings and F_0;
    one written before it kept them reads back with none (the elastic way refuses it)."""
    F = np.array([1.0, 2.0, 4.0])
    model = (_curve(F, 0.03, 90.0, 1.1), _curve(F, 2.4, 160.0, 1.0))
    np.savez(tmp_path / "new.npz", **PointObjective.pack(model))
    with np.load(tmp_path / "new.npz") as z:
        back = PointObjective.unpack({n: z[n] for n in z.files})
    for c, b in zip(model, back):
        assert all(np.array_equal(getattr(c, k), getattr(b, k))
                   for k in ("velocity", "force", "speed", "reading", "static_force"))
    np.savez(tmp_path / "old.npz", **{k: v for k, v in PointObjective.pack(model).items()
                                      if k in ("velocity", "force", "speed")})
    with np.load(tmp_path / "old.npz") as z:
        old = PointObjective.unpack({n: z[n] for n in z.files})
    assert all(c.reading is None and c.static_force is None for c in old)
    assert np.array_equal(old[1].force, model[1].force)


def test_the_report_shows_the_points_both_ways_and_says_which_the_fit_uses(constructed):
    """fitted.md's table: a row a point with its model V_s and residual each way, then chi2/dof
    each way and the range of the converted F_d over the contact F_d (0.95 to 1.1 here)."""
    from rig.study.reproduce_fitted import KEPT_KEYS
    from rig.study.reproduce_fitted_report import markdown

    b = constructed[2]
    f = {"model": "x", "selection": "lowest held-out chi2", "models": {}, "dashpot_scan": [],
         "steel": {"youngs_modulus_Pa": 1.9e11, "youngs_modulus_std_Pa": 1e10, "published_modulus_Pa": 1.93e11,
                   "gravity_speed_m_per_s": 580.0, "magnetic_speed_m_per_s": 688.0},
         "targets": [], **dict.fromkeys(KEPT_KEYS), "table1_points_both_conversions": b}
    md = markdown(f)
    p = b["points"][3]
    row = (f"| 2.38 | 7.8 | 220 | {p['model_V_s_contact_force_m_per_s']:.1f} | {p['residual_contact_force_sd']:+.2f} | "
           f"{p['model_V_s_elastic_conversion_m_per_s']:.1f} | {p['residual_elastic_conversion_sd']:+.2f} |")
    assert row in md and md.count("| 0.0 | ") == 3
    assert (f"chi2/dof (4 dof): (1) {b['chi2_per_dof_contact_force']:.3f}, "
            f"(2) {b['chi2_per_dof_elastic_conversion']:.3f}") in md
    assert "on the curves' shots: 0.950 to 1.100. The fit uses (1)." in md
