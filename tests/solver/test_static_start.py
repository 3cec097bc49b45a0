"""The rig starts from exact static equilibrium: nothing moves before impact."""
import numpy as np
from conftest import ptfe_rig

from rig import ChainProblem, SaveAt, solve


def test_published_ptfe_chain_at_rest_stays_at_rest():
    # 52 PTFE beads + magnetic bead, gravity and 2.38 N, no striker: after 2 ms no bead
    # moves faster than 1e-9 m/s (acceptance of the static start).
    chain = ptfe_rig(top_force=2.38, striker=False)
    p, save = ChainProblem.from_chain(chain), SaveAt({"wall": chain.wall_probe()})
    sol = solve(p, 2e-3, save=save)
    assert np.max(np.abs(sol.final_v)) < 1e-9
    # the wall carries the weight of everything plus the magnet force, unchanged
    expected = 9.80665 * chain.masses.sum() + 2.38
    assert np.max(np.abs(sol.forces["wall"] - expected)) < 1e-9 * expected


def test_static_forces_are_weight_above_plus_magnet():
    chain = ptfe_rig(n=5, top_force=2.38)
    F = chain.static_forces()
    assert F[0] == 0.0  # the striker just touches
    m = chain.masses
    assert np.allclose(F[1:], 9.80665 * np.cumsum(m) + 2.38, rtol=1e-15)
    # the Hertz law at the static overlaps gives back the static forces
    A = chain.contact_constants()
    d0 = chain.static_overlaps()
    assert np.allclose(A[1:] * d0[1:] ** 1.5, F[1:], rtol=1e-13)
