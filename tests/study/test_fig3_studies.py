"""The Fig. 3 studies: identifiability on virtual shots (its counting and its seed), the
figures' sensitivities against a difference taken by hand, and the window search."""
from __future__ import annotations

import math
from dataclasses import astuple
from pathlib import Path

import numpy as np
import pytest

from rig.errors import RigError
from rig.fit.observations.objective import ObservationObjective
from rig.fit.observations.reading import read_observations
from rig.fit.parameters import parse_parameter
from rig.study import fig3
from rig.study.identifiability import coverage
from rig.study.sensitivity import STEP, Figures, sensitivities, window

ROOT = Path(__file__).resolve().parents[2]


def test_the_fig3_observations_are_the_scenario_files():
    from_file = read_observations(ROOT / "scenarios" / "daraio2006_fig3_observations.toml", fig3.GRAVITY)
    assert [astuple(o)[:-1] for o in fig3.observations()] == [astuple(o)[:-1] for o in from_file]


def test_targets_are_ranges_of_known_kinds():
    names = [t.name for t in fig3.TARGETS]
    assert len(names) == len(set(names)) == 7
    for t in fig3.TARGETS:
        assert t.lo < t.hi
        assert not t.holds(math.nan)
    speed = fig3.TARGETS[0]
    assert speed.holds(129.0) and not speed.holds(115.9) and not speed.holds(142.1)


def test_window_of_a_known_interval():
    calls = []

    def holds(xs):
        calls.append(len(xs))
        return [() if 2.0 <= x <= 5.0 else (("low",) if x < 2.0 else ("high",)) for x in xs]

    low, high = window(holds, 3.0, 0.5, 20.0, points=7, resolution=0.001)
    assert 2.0 <= low.value < 2.0 * math.exp(0.001)  # the passing side of the edge, within the resolution
    assert 5.0 / math.exp(0.001) < high.value <= 5.0
    assert (low.open, high.open, low.failing, high.failing) == (False, False, ("low",), ("high",))
    assert len(calls) < 20  # bisection: both edges each call, not a fine scan


def test_window_open_where_the_scan_holds_and_none_where_the_centre_fails():
    low, high = window(lambda xs: [x >= 1.0 for x in xs], 3.0, 0.5, 9.0, points=5, resolution=0.01)
    assert high.open and high.value == pytest.approx(9.0) and not low.open
    assert 1.0 <= low.value < 1.0 * math.exp(0.01)
    assert window(lambda xs: [x > 4.0 for x in xs], 3.0, 1.0, 9.0) is None


GRAVITY_SPEED_AND_DURATION = tuple(o for o in fig3.observations()
                                   if o.shot.scene == fig3.GRAVITY and o.kind in ("speed", "duration"))


def test_coverage_counts_the_intervals_and_the_seed_repeats_the_data():
    """Youngs modulus from the gravity shot's speed and duration (a cheap set: one scene, Hertz's law).
    Another seed needs one data set only to show that its data differ (its first fit's estimate)."""
    param = parse_parameter("chain.youngs_modulus=0.4 GPa:2 GPa")
    a = coverage(param, 0.84e9, (), GRAVITY_SPEED_AND_DURATION, n=3, seed=7)
    b = coverage(param, 0.84e9, (), GRAVITY_SPEED_AND_DURATION, n=3, seed=7)
    c = coverage(param, 0.84e9, (), GRAVITY_SPEED_AND_DURATION, n=1, seed=8)
    assert a.estimates == b.estimates and a.stds == b.stds and a.seed == 7
    assert c.n == 1 and a.estimates[0] != c.estimates[0]
    est, sd = np.array(a.estimates), np.array(a.stds)
    by_hand = [bool(ok and e - 1.96 * s <= 0.84e9 <= e + 1.96 * s) for ok, e, s in zip(a.converged, est, sd)]
    assert list(a.holds) == by_hand and a.count == sum(by_hand)
    assert all(a.converged)
    # the speed (10%) alone bounds E to about 30% (V ~ E^(1/3)): each estimate within 4 sd of the truth
    assert np.all(np.abs(est - 0.84e9) < 4 * sd) and np.all(sd < 0.5e9)
    d = a.as_dict()
    assert d["holding"] == a.count and d["n"] == 3 and d["seed"] == 7
    for (lo, hi), e, s in zip(a.intervals, est, sd):  # +- 1.96 sd, cut at the bounds
        assert (lo, hi) == pytest.approx((max(e - 1.96 * s, 0.4e9), min(e + 1.96 * s, 2e9)))
    widths = [(hi - lo) / 1.6e9 for lo, hi in a.intervals]
    assert d["median_width_over_span"] == pytest.approx(np.median(widths)) and d["median_width_over_span"] < 1


def test_a_truth_outside_its_bounds_is_refused():
    with pytest.raises(RigError, match="chain.youngs_modulus truth"):
        coverage(parse_parameter("chain.youngs_modulus=0.4 GPa:2 GPa"), 3e9, (), GRAVITY_SPEED_AND_DURATION, n=1)


def test_sensitivity_is_the_hand_computed_central_difference():
    fig = Figures(fig3.PARAMETER_SET)
    result = sensitivities(fig)
    assert all(result["holds"].values())  # the parameter set meets Fig. 3
    # by hand: the gravity speed alone, its own objective, E at 0.84 GPa e^(+-STEP); its shots
    # at the study's numerics (the step calibrated once at the set, as a study's fits share it)
    speed = fig3.TARGETS[0].figure
    obj = ObservationObjective(fig3.GRAVITY, (parse_parameter("chain.youngs_modulus=0.2 GPa:3 GPa"),), (speed,),
                               fig3.PARAMETER_SET)
    obj.pilot = fig.objective.pilot
    (down,), (up,) = obj.evaluate([np.array([0.84e9 * math.exp(-STEP)]), np.array([0.84e9 * math.exp(STEP)])])
    by_hand = (math.log(up) - math.log(down)) / (2 * STEP)
    assert result["d_ln_figure_d_ln_p"]["gravity_speed"]["chain.youngs_modulus"] == pytest.approx(by_hand, rel=1e-3)
    # the solitary wave's speed goes as E^(1/3) at a fixed force; the force itself moves a little with E
    assert 0.25 < by_hand < 0.45
    # the static hold's yield acts only under the magnet: the gravity shot does not see it
    assert result["d_ln_figure_d_ln_p"]["gravity_speed"]["chain.static_yield_ratio"] == 0.0


def test_a_parameter_the_observations_do_not_see_is_reported_not_fitted():
    """The static hold's yield acts under the magnet only: the gravity shot's figures do not move with it."""
    c = coverage(parse_parameter("chain.static_yield_ratio=0.2:1"), 0.6, fig3.PARAMETER_SET,
                 GRAVITY_SPEED_AND_DURATION, n=2, seed=0)
    assert "do not see it" in c.refused and c.n == 0 and c.count == 0
    assert c.as_dict()["refused"] == c.refused and c.as_dict()["mean_estimate"] is None


def test_a_yield_pressure_given_replaces_the_sets_yield_force():
    """The kept set gives the contacts' yield as a pressure, Fig. 3's set as a force: a --set
    of either replaces the set's other (a scene takes one of the two), so the kept set can be
    asked about (rig reproduce daraio2006 --identifiability --set chain.yield_pressure=...)."""
    from rig.cli import build_parser
    from rig.cli.fig3_studies import parameter_set

    args = build_parser().parse_args(["reproduce", "daraio2006", "--sensitivity", "--out", "unused",
                                      "--set", "chain.yield_pressure=59.5 MPa"])
    merged = parameter_set(args)
    assert "chain.yield_pressure=59.5 MPa" in merged and not any(o.startswith("chain.yield_force") for o in merged)
    assert len(merged) == len(fig3.PARAMETER_SET)
