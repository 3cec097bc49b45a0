"""A study's inputs are drawn for a whole batch in one compiled call (instruments.streams),
with the numbers numpy's generator gives each shot's own stream: compared here, to the
last bit, with numpy's Generator methods drawing them one shot at a time."""
import math

import numpy as np
import pytest
from scipy import stats

from rig.study.batch import batch_inputs, shot_inputs
from rig.study.distributions import parse_vary
from rig.study.montecarlo import MonteCarloStudy

VARY = ("striker.velocity=normal(0.89 m/s, 0.01 m/s)", "chain.bead_mass=normal(0.1226 g, 0.0008 g)",
        "gauges.upper.gain=lognormal(1, 0.05)", "magnet.force=uniform(2 N, 3 N)",
        "gauges.lower.gain=truncnormal(1, 0.1, 0.9, 1.2)")


def _numpy_inputs(study: MonteCarloStudy, i: int, n_plain: int, design=None):
    """Shot i's inputs as numpy's Generator methods draw them from its stream."""
    child = np.random.SeedSequence(study.seed, spawn_key=(i,))
    rng = np.random.default_rng(child)
    x, masses = {}, None
    for k, d in enumerate(study.dists):
        p = d.params
        if d.key == "chain.bead_mass":
            masses = rng.normal(p[0], p[1], n_plain)
            x[d.key] = float(np.mean(masses))
            continue
        if design is not None:
            x[d.key] = float(design[i, k])
        elif d.kind == "normal":
            x[d.key] = float(rng.normal(p[0], p[1]))
        elif d.kind == "uniform":
            x[d.key] = float(rng.uniform(p[0], p[1]))
        elif d.kind == "lognormal":
            s2 = math.log1p((p[1] / p[0]) ** 2)
            x[d.key] = float(rng.lognormal(math.log(p[0]) - 0.5 * s2, math.sqrt(s2)))
        else:
            a, b = (p[2] - p[0]) / p[1], (p[3] - p[0]) / p[1]
            x[d.key] = float(stats.truncnorm.ppf(rng.uniform(), a, b, loc=p[0], scale=p[1]))
    return x, masses, int(child.generate_state(1, np.uint64)[0] >> np.uint64(1))


def _same(a, b) -> bool:
    return np.array_equal(np.asarray(a, float).view(np.uint64), np.asarray(b, float).view(np.uint64))


@pytest.mark.parametrize("seed", [0, 11, 2**40 + 3, 2**63 - 1])
def test_a_batch_draws_each_shots_inputs_as_numpy_does_for_it_alone(seed):
    study = MonteCarloStudy("ptfe52_magnetic", tuple(parse_vary(VARY)), 300, seed=seed)
    got = batch_inputs(study, 250, 300, 52)
    for s, i in enumerate(range(250, 300)):
        x, masses, instrument_seed = _numpy_inputs(study, i, 52)
        assert list(got[s][0]) == list(x)
        assert _same(list(got[s][0].values()), list(x.values())), (i, got[s][0], x)
        assert _same(got[s][1], masses) and got[s][2] == instrument_seed
    assert shot_inputs(study, 260, 52)[2] == got[10][2]


def test_a_sobol_design_sets_the_keys_but_the_masses_are_still_drawn():
    study = MonteCarloStudy("ptfe52_magnetic", tuple(parse_vary(VARY)), 8, seed=3)
    design = np.random.default_rng(0).uniform(size=(8, len(VARY)))
    got = batch_inputs(study, 0, 8, 52, design)
    for i in range(8):
        x, masses, instrument_seed = _numpy_inputs(study, i, 52, design)
        assert _same(list(got[i][0].values()), list(x.values())) and _same(got[i][1], masses)
        assert got[i][2] == instrument_seed


@pytest.mark.parametrize("seed", [-1, 2**63, True, 1.5, "3"])
def test_a_seed_no_stream_can_have_is_refused_in_one_line(seed):
    from rig.errors import RigError

    with pytest.raises(RigError, match=r"--seed = .*: a whole number from 0 to 2\^63 - 1"):
        MonteCarloStudy("ptfe52_magnetic", tuple(parse_vary(VARY[:1])), 4, seed=seed)


def test_numpys_integers_are_taken_as_seeds():
    assert MonteCarloStudy("ptfe52_magnetic", tuple(parse_vary(VARY[:1])), 4, seed=np.int64(9)).seed == 9
