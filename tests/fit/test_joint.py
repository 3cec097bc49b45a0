"""rig.fit.joint (one parameter set fitted to several objectives) and rig.fit.crossval (the
linearised leave-one-out), on real fits of small problems: Hertz's modulus fitted to Table 1's
five gravity-only points and Fig. 3's gravity-only speed."""
import numpy as np
import pytest

from rig.errors import RigError
from rig.fit.crossval import held_out_residuals, leverages
from rig.fit.fitting import fit
from rig.fit.joint import JointObjective
from rig.fit.observations.objective import ObservationObjective
from rig.fit.parameters import parse_parameters
from rig.fit.points import PointObjective
from rig.study.fitted_families import fig3_observations, magnetic_observation, magnetic_points, table1_points

E = parse_parameters(["chain.youngs_modulus=0.2 GPa:4 GPa"])


@pytest.fixture(scope="module")
def gravity():
    pts, obs = table1_points(), fig3_observations()
    speed = tuple(o for o in obs if o.kind == "speed" and not magnetic_observation(o))
    return pts.subset(np.flatnonzero(~magnetic_points(pts))), speed


@pytest.fixture(scope="module")
def points_fit(gravity):
    """Hertz's modulus fitted to the five gravity-only points: the objective (its pilot
    calibrated) and its fit, which both tests below need."""
    pts, _ = gravity
    points = PointObjective("ptfe52_gravity", E, pts)
    return points, fit(points)


def test_the_joint_fit_is_the_sum_of_its_parts_and_lies_between_their_own_fits(gravity, points_fit):
    _, speed = gravity
    (points, points_alone), observed = points_fit, ObservationObjective("ptfe52_gravity", E, speed)
    joint = JointObjective([points, observed])
    assert joint.n_data == 6
    r = fit(joint)
    assert r.converged and r.dof == 5
    (m_points,) = points.evaluate([r.estimate])
    (m_obs,) = observed.evaluate([r.estimate])
    parts = np.concatenate((points.residuals(m_points, np.zeros(0)), observed.residuals(m_obs, np.zeros(0))))
    np.testing.assert_allclose(r.residuals, parts, rtol=1e-9)
    assert r.chi2 == pytest.approx(float(parts @ parts), rel=1e-9)
    # one modulus for both: a compromise between what each data set wants alone (the points'
    # speeds, about 165 m/s at F_d ~ 2-6 N, ask for a stiffer chain than the 129 m/s shot)
    alone = sorted((float(points_alone.estimate[0]), float(fit(observed).estimate[0])))
    assert alone[0] < r.estimate[0] < alone[1]
    assert alone[1] / alone[0] > 1.5  # the two data sets do disagree: the test can tell
    # the model packed for the cache comes back whole
    again = joint.unpack(joint.pack(r.model))
    np.testing.assert_array_equal(joint.residuals(again, np.zeros(0)), r.residuals)


def test_a_joint_fit_refuses_parts_with_other_parameters(gravity):
    pts, speed = gravity
    n = parse_parameters(["chain.youngs_modulus=0.2 GPa:4 GPa", "chain.contact_exponent=1.05:2.6"])
    with pytest.raises(RigError, match="the same fitted parameters in every part"):
        JointObjective([PointObjective("ptfe52_gravity", E, pts), ObservationObjective("ptfe52_gravity", n, speed)])


def test_the_linearised_leave_one_out_is_exact_for_a_linear_model():
    rng = np.random.default_rng(3)
    X = np.column_stack((np.ones(12), rng.uniform(0, 1, 12), rng.uniform(0, 1, 12)))
    y = X @ [1.0, 2.0, -0.5] + rng.normal(0, 0.1, 12)
    beta = np.linalg.lstsq(X, y, rcond=None)[0]
    exact = [y[i] - X[i] @ np.linalg.lstsq(np.delete(X, i, 0), np.delete(y, i), rcond=None)[0] for i in range(12)]
    # residuals r = model - data, the fit's convention; Jacobian of r is X
    np.testing.assert_allclose(held_out_residuals(X, X @ beta - y), -np.array(exact), rtol=1e-9)
    assert leverages(X).sum() == pytest.approx(3.0)  # trace of the hat matrix: the parameters' count


def test_the_linearised_leave_one_out_matches_exact_refits_of_a_real_fit(gravity, points_fit):
    """Hertz's modulus from the five gravity-only points: each point's held-out residual,
    linearised at the fit to all five, against the fit to the other four. A point's residual
    depends on its own data and the curve alone: the held-out one is the all-points
    objective's at the four's estimate. The pilot is calibrated on the start values' shots,
    not the data: the four points' objectives take the five's (the same Pilot, measured)."""
    pts, _ = gravity
    points, r = points_fit
    linear = held_out_residuals(r.jacobian, r.residuals)
    exact = np.empty(pts.n)
    for i in range(pts.n):
        others = PointObjective("ptfe52_gravity", E, pts.subset([k for k in range(pts.n) if k != i]))
        others.pilot = points.pilot
        rest = fit(others)
        (model,) = points.evaluate([rest.estimate])
        exact[i] = points.residuals(model, np.zeros(0))[i]
    print("linearised", linear, "exact", exact)
    assert np.all(np.abs(linear) >= np.abs(r.residuals))  # held out, a point is never predicted better
    np.testing.assert_allclose(linear, exact, atol=0.02, rtol=0.03)  # measured: within 1%
