"""The fit stops at the optimum of the true derivative and reports its covariance: on a
pulse whose arrival moves with the parameter by a fifth of its width over one
finite-difference step (a scope trace's case: rig.fit.fitting.FD_STEP), the fit with
central differences stops where the analytic Jacobian's Gauss-Newton step is < 0.1 sd and
gives its standard deviation to the central difference's error, (shift / width)^2 = 5%;
with forward differences (a secant) it stops 0.14-0.3 sd short. The MCMC posterior
(rig.fit.posterior) agrees with that covariance, and resumes."""
import numpy as np
import pytest

from rig.fit.fitting import fit
from rig.fit.parameters import FitParameter

T = np.linspace(0.0, 2.0e-3, 2001)  # s
DISTANCE, WIDTH, SIGMA = 0.1, 40e-6, 0.01  # m, s, noise sd (volts of a unit pulse)
SPEED = 150.0  # m/s: true


def pulse(speed):
    return np.exp(-(((T - DISTANCE / speed) / WIDTH) ** 2))


def dpulse(speed):
    s = (T - DISTANCE / speed) / WIDTH
    return pulse(speed) * 2 * s / WIDTH * DISTANCE / speed ** 2


class PulseObjective:
    """One Gaussian pulse arriving at DISTANCE / speed, with white noise SIGMA; no nuisance."""

    def __init__(self, data, central):
        self.params = (FitParameter("chain.youngs_modulus", 100.0, 300.0, "1"),)
        self.data, self.central_differences = data, central

    def spec(self):
        return {"kind": "pulse", "central": self.central_differences}

    def start(self):
        return np.array([148.0])

    data_name = "the pulse"

    @property
    def n_data(self):
        return self.data.size

    def evaluate(self, thetas):
        return [pulse(float(t[0])) for t in thetas]

    pack = unpack = staticmethod(lambda z: z)

    def nuisance_start(self):
        return np.zeros(0), np.zeros(0), np.zeros(0)

    def residuals(self, model, eta):
        return (model - self.data) / SIGMA

    def nuisance_jacobian(self, model, eta):
        return np.zeros((T.size, 0))

    def nuisance_report(self, eta):
        return {}


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_central_differences_give_the_derivatives_covariance(seed):
    data = pulse(SPEED) + SIGMA * np.random.default_rng(seed).standard_normal(T.size)
    r = fit(PulseObjective(data, central=True))
    assert r.converged
    c = float(r.estimate[0])
    J = dpulse(c) / SIGMA
    sd = float(np.sqrt(max(1.0, r.chi2_reduced) / (J @ J)))
    assert float(r.std[0]) == pytest.approx(sd, rel=0.05)
    assert abs(gauss_newton_step(c, data)) < 0.1 * sd
    forward = fit(PulseObjective(data, central=False))
    assert abs(gauss_newton_step(float(forward.estimate[0]), data)) > 0.1 * sd


def gauss_newton_step(speed, data):
    """The Gauss-Newton step (m/s) from ``speed`` with the analytic Jacobian."""
    J = dpulse(speed) / SIGMA
    return -float(J @ ((pulse(speed) - data) / SIGMA)) / float(J @ J)


def test_posterior_matches_the_covariance_and_resumes(tmp_path):
    """On the pulse (nearly linear about the optimum at this noise), emcee's posterior has
    the fit's median and sd: with 32 walkers x 100 steps (half discarded; the chain's
    autocorrelation time is about 5 steps, 8-16 with 8 walkers: some 300 independent
    samples) the median lies within 0.5 sd of the estimate and the samples' sd within 25%
    of the fit's (4 standard errors each or more). The same seed gives the same chain, and
    a run stopped after 50 steps and asked for 100 goes on to the same chain. (Many walkers
    and few steps: each step rewrites posterior.h5, which costs more than its candidates.)"""
    pytest.importorskip("emcee")
    from rig.fit.posterior import sample

    data = pulse(SPEED) + SIGMA * np.random.default_rng(4).standard_normal(T.size)
    obj = PulseObjective(data, central=True)
    r = fit(obj)
    post = sample(obj, r, tmp_path / "a", walkers=32, steps=100, seed=7)
    sd = float(r.std[0])
    assert post.steps == 100 and post.burn == 50 and post.samples.shape == (32 * 50, 1)
    assert abs(post.median[0] - r.estimate[0]) < 0.5 * sd
    assert float(np.std(post.samples[:, 0])) == pytest.approx(sd, rel=0.25)
    assert post.ci95[0, 0] < r.estimate[0] < post.ci95[0, 1]
    sample(obj, r, tmp_path / "b", walkers=32, steps=50, seed=7)
    resumed = sample(obj, r, tmp_path / "b", walkers=32, steps=100, seed=7)
    assert np.array_equal(resumed.samples, post.samples)
