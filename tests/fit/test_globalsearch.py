"""rig.fit.globalsearch (differential evolution before the local fit) on a small synthetic
least-squares problem with many local minima, so that every assertion is about the search
itself and costs milliseconds: Rastrigin's function as residuals."""
import numpy as np
import pytest

from rig.fit.fitting import fit
from rig.fit.globalsearch import distinct_members, search, searched_fit
from rig.fit.multistart import DISTINCT
from rig.fit.parameters import FitParameter

CENTRE = (2.3, -1.7)
AMPLITUDE = 10.0


class Rastrigin:
    """Residuals (x_i - c_i) and sqrt(2A) sin(pi (x_i - c_i)): chi2 = sum (x - c)^2 + A sum
    (1 - cos 2 pi (x - c)), Rastrigin's function shifted to c. Its local minima lie near c
    plus whole numbers, chi2 about the squared distance to c there; the global one at c,
    chi2 0. Bounds -5.12..5.12 each; the fit starts at the middle, 0, in the basin of the
    local minimum near (0.3, 0.3)."""

    central_differences = False
    n_data = 4
    data_name = "Rastrigin"

    def __init__(self):
        self.params = tuple(FitParameter(f"x{i}", -5.12, 5.12, "1") for i in range(2))
        self.c = np.array(CENTRE)
        self.evaluated = 0

    def start(self):
        return np.zeros(2)

    def spec(self) -> dict:
        return {"kind": "rastrigin", "centre": list(CENTRE), "amplitude": AMPLITUDE}

    def evaluate(self, thetas):
        self.evaluated += len(thetas)
        out = []
        for t in thetas:
            d = np.asarray(t, float) - self.c
            out.append(np.concatenate((d, np.sqrt(2 * AMPLITUDE) * np.sin(np.pi * d))))
        return out

    @staticmethod
    def pack(model):
        return {"r": model}

    @staticmethod
    def unpack(z):
        return z["r"]

    @staticmethod
    def residuals(model, eta):
        return model

    @staticmethod
    def nuisance_start():
        return np.zeros(0), np.zeros(0), np.zeros(0)

    @staticmethod
    def nuisance_jacobian(model, eta):
        return np.zeros((4, 0))

    @staticmethod
    def nuisance_report(eta):
        return {}


def test_the_local_fit_stops_in_a_local_minimum_that_the_global_search_passes():
    """From the bounds' middle the local fit converges, but to a local minimum (chi2 about
    8, two whole steps from c in each coordinate); the global search finds c, its local fit
    polishes it to chi2 ~ 0, and both optima are reported, the global one first."""
    local = fit(Rastrigin())
    assert local.converged and local.chi2 > 4.0
    assert np.all(np.abs(local.estimate - np.array(CENTRE)) > 1.5)
    best, optima, found = searched_fit(Rastrigin(), starts=2, generations=60, seed=0)
    assert found is not None and found.best_chi2 < 1.0  # the search alone lands in c's basin
    assert best.converged and best.chi2 < 1e-8
    assert best.estimate == pytest.approx(CENTRE, abs=1e-5)
    assert len(optima) >= 2 and optima[0].chi2 == pytest.approx(best.chi2)
    assert any(o.chi2 == pytest.approx(local.chi2, rel=1e-6) for o in optima[1:])  # the own start's minimum
    # the record: the seed, each generation's best (never worse), the population best first
    block = found.as_dict(["x0", "x1"])
    assert block["seed"] == 0 and block["population"] == 20 and block["candidates"] == found.candidates
    history = np.array(found.history)
    assert np.all(np.diff(history) <= 0) and history[-1] == found.best_chi2
    assert list(found.population_chi2) == sorted(found.population_chi2)
    assert found.population[0] == pytest.approx(found.best)


def test_a_search_stopped_and_run_again_replays_its_candidates_and_ends_where_an_unstopped_one_does(tmp_path):
    """Every candidate goes through the evaluation cache: a search cut short (its first 5
    generations, as a kill leaves it) and run again with the same seed meets the same
    candidates, solves only those it had not, and ends bit for bit where one search run
    through ends; run a third time it solves nothing. Another seed draws other members."""
    whole = search(Rastrigin(), 40, seed=7)
    cut = search(Rastrigin(), 5, seed=7, cache_folder=tmp_path)
    again = search(Rastrigin(), 40, seed=7, cache_folder=tmp_path)
    assert cut.solved == cut.candidates and 0 < cut.candidates < again.candidates
    assert again.solved == again.candidates - cut.candidates  # the first 5 generations replayed
    assert again.best == whole.best and again.best_chi2 == whole.best_chi2 and again.history == whole.history
    third = search(Rastrigin(), 40, seed=7, cache_folder=tmp_path)
    assert third.solved == 0 and third.best == whole.best
    other = search(Rastrigin(), 5, seed=8)
    assert other.population != cut.population


def test_the_members_a_local_fit_starts_from_are_distinct():
    """distinct_members takes the last population best first, skipping members within
    DISTINCT of one already taken in every parameter."""
    found = search(Rastrigin(), 30, seed=0)
    params = Rastrigin().params
    taken = distinct_members(found, params, 5, DISTINCT)
    assert 1 <= len(taken) <= 5 and taken[0] == pytest.approx(found.population[0])
    span = np.array([p.hi - p.lo for p in params])
    for i, a in enumerate(taken):
        for b in taken[:i]:
            assert np.any(np.abs(a - b) > DISTINCT * span)
