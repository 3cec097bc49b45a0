"""What `rig reproduce daraio2006 --fitted` fits within and keeps: every fitted key's bounds
with their source, Table 1's striker velocities and the drops they need, the recorded set
of the elastic-plastic + dashpot family meeting every target (one batch of its shots), and
the one-dimensional windows around a set."""
import math
import re

import numpy as np
import pytest

from rig.fit.parameters import parse_parameters
from rig.fit.points import VELOCITY_FACTORS, striker_drops
from rig.study.fitted_bounds import SOURCES
from rig.study.fitted_families import EPD_START, FAMILIES, fig3_observations, table1_points
from rig.study.fitted_windows import windows

EPD = next(f for f in FAMILIES if f.name == "elastic-plastic + dashpot")


def test_every_fitted_key_has_literature_bounds_with_a_source():
    """Each family's fitted keys are bounded as rig.study.fitted_bounds states, each with a
    source naming a year; the dashpot reaches 0.5 kg/s and beyond, PTFE's modulus spans its
    quasi-static 0.4 GPa to above the published dynamic 1.46 GPa, the yield pressure spans
    1.6 x to 3 x a yield stress of about 10-40 MPa."""
    for family in FAMILIES:
        for p in parse_parameters(family.params):
            assert re.search(r"(19|20)\d\d", SOURCES[p.key]), p.key
    bounds = {p.key: p for f in FAMILIES for p in parse_parameters(f.params)}
    assert bounds["chain.contact_damping"].hi >= 0.5
    assert bounds["chain.youngs_modulus"].lo <= 0.4e9 and bounds["chain.youngs_modulus"].hi > 1.46e9
    assert bounds["chain.yield_pressure"].lo <= 1.6 * 10e6 and bounds["chain.yield_pressure"].hi >= 3 * 30e6


def test_table1_curves_reach_2_6_m_per_s_and_each_drop_is_stated():
    """The curves' striker velocities reach past 2.6 m/s; each needs a drop h = v^2 / 2g (no
    loss on the way), released above the tube's top where h exceeds the tube left above the
    chain (holder.length less the stack and the striker)."""
    v = 0.89 * np.array(VELOCITY_FACTORS)
    assert v.max() >= 2.6
    d = striker_drops("ptfe52_gravity", [], v)
    assert d["holder_length_m"] == pytest.approx(0.4)
    assert d["free_length_m"] == pytest.approx(0.4 - 52 * 4.76e-3 - 5e-3 - 6.772e-3, abs=2e-4)
    for drop, speed in zip(d["drops"], v):
        assert math.sqrt(2 * 9.80665 * drop["drop_height_m"]) == pytest.approx(speed, rel=1e-12)
        assert drop["above_tube_m"] == pytest.approx(max(drop["drop_height_m"] - d["free_length_m"], 0.0))
    assert d["drops"][-1]["drop_height_m"] == pytest.approx(0.363, abs=1e-3)  # 2.67 m/s: 36 cm
    assert striker_drops("ptfe52_gravity", ["holder.vertical=false"], v)["drops"] == []


def test_the_recorded_set_meets_every_table1_and_fig3_target():
    """EPD_START, where the family's joint fit stops, meets every target (its Table 1 curves
    and Fig. 3 shots in one batch each), close to two edges: the gravity-only speed just
    under 142 m/s and the train's 2 pulses."""
    from rig.study.fitted_windows import Targets
    from rig.study.reproduce_fitted_report import misses

    theta = np.array([v for _, v in EPD_START])
    assert [k for k, _ in EPD_START] == [p.split("=")[0] for p in EPD.params]
    (row,) = Targets(EPD, table1_points(), fig3_observations(), theta).rows([theta])
    assert misses(row) == []
    assert row["table1_unreachable"] == 0 and row["table1_chi2_per_dof"] <= 1.0 and row["table1_rms_relative"] <= 0.07
    f = row["fig3"]
    assert 140.0 < f["gravity_speed_m_per_s"] <= 142.0 and f["gravity_pulses_lower_gauge"] == 2
    assert f["wall_peak_magnetic_N"] > 2 * f["wall_peak_gravity_N"]


class Ring:
    """Targets on a small synthetic problem: a candidate misses "low" below 0.8 x and
    "high" above 1.1 x the set's value of its first parameter, and nothing for the second."""

    def __init__(self):
        self.params = parse_parameters(["chain.youngs_modulus=0.4 GPa:3 GPa", "holder.friction=0 N:1 N"])

    @staticmethod
    def missed(thetas):
        return [("low",) if t[0] < 0.8e9 else ("high",) if t[0] > 1.1e9 else () for t in thetas]


def test_a_window_is_bisected_to_its_edges_and_names_what_fails_past_them():
    w = windows(Ring(), [1e9, 0.2])
    e = w["chain.youngs_modulus"]
    assert e["window"][0] == pytest.approx(0.8e9, rel=0.003) and e["window"][1] == pytest.approx(1.1e9, rel=0.003)
    assert e["window"][0] >= 0.8e9 and e["window"][1] <= 1.1e9  # the passing side of each edge
    assert e["relative"] == pytest.approx([-0.2, 0.1], abs=0.003)
    assert e["failing_below"] == ["low"] and e["failing_above"] == ["high"] and e["open"] == [False, False]
    d = w["holder.friction"]  # a bound at 0: scanned from a hundredth of the value; nothing fails
    assert d["scan"] == [0.002, 1.0] and d["open"] == [True, True] and d["window"] == pytest.approx([0.002, 1.0])
