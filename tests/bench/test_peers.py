"""The benchmark's peer solvers against the project's converged reference (SRKN6b, dt = tau/400).

Both DOP853 peers converge as rtol falls, the compiled one carries scipy's coefficients and
gives scipy's numbers where the two step-size rules pick the same steps, and reaches 1e-7 on a
smooth problem; LAMMPS, where installed, computes the chain's forces and converges at order 2.
"""
import importlib

import numpy as np
import pytest
from chains import STEEL, ptfe_rig, record_contacts, steel_sonic_vacuum

from rig import Bead, Chain, ChainProblem, RigError, Wall, solve
from rig.bench import lammps, peers
from rig.bench.kernels import dop853
from rig.solver.kernels.forces import hertz_forces
from rig.solver.stepsize import contact_time_scale

CASES = {  # name: (chain, probe contact, t_end s)
    "sonic-vacuum": (lambda: steel_sonic_vacuum(n=40), 20, 0.3e-3),
    "ptfe": (lambda: ptfe_rig(n=30), 15, 0.6e-3),
}
needs_lammps = pytest.mark.skipif(lammps.executable() is None,
                                  reason="LAMMPS not installed (apt-get install lammps)")


def _error(force, ref, scale=None):
    return float(np.max(np.abs(force - ref)) / (np.max(ref) if scale is None else scale))


@pytest.fixture(scope="module")
def case():
    """{name: (problem, save, t_end, reference force)}, each reference solved once."""
    out = {}
    for name, (build, contact, t_end) in CASES.items():
        chain = build()
        p = ChainProblem.from_chain(chain)
        save = record_contacts(chain, contact, sample_interval=1e-6)
        ref = solve(p, t_end, save=save, dt=contact_time_scale(p) / 400).forces[f"c{contact}"]
        out[name] = (p, save, t_end, ref)
    return out


def test_the_coefficients_are_scipys():
    scipy_table = importlib.import_module("scipy.integrate._ivp.dop853_coefficients")
    for name in ("C", "A", "B", "E3", "E5", "D"):
        assert np.array_equal(getattr(dop853, name), getattr(scipy_table, name)), name
    assert (dop853.N_STAGES, dop853.N_STAGES_EXTENDED) == (scipy_table.N_STAGES, scipy_table.N_STAGES_EXTENDED)


@pytest.mark.parametrize("name", CASES)
@pytest.mark.parametrize("peer", [peers.numba_dop853, peers.scipy_dop853])
def test_dop853_converges_to_the_reference(case, name, peer):
    p, save, t_end, ref = case[name]
    runs = [peer(p, save, t_end, rtol) for rtol in (1e-6, 1e-9)]
    errors = [_error(r.force, ref) for r in runs]
    assert errors[1] < errors[0] / 10, errors
    assert errors[1] < 1e-4, errors
    for r in runs:
        assert r.force.shape == ref.shape
        assert r.rhs_evaluations >= 12 * r.steps and r.cpu_s > 0


def test_numba_dop853_gives_scipys_numbers(case):
    p, save, t_end, ref = case["sonic-vacuum"]
    # at rtol 1e-6 neither step-size rule reaches the limits where they differ (growth 6 against
    # 10, shrinking 0.333 against 0.2): the same steps, the same numbers to rounding
    ours, theirs = peers.numba_dop853(p, save, t_end, 1e-6), peers.scipy_dop853(p, save, t_end, 1e-6)
    assert ours.steps == theirs.steps
    assert _error(ours.force, theirs.force) < 1e-10
    # elsewhere the step sequences part: each error of the size of the other's
    for rtol in (1e-8, 1e-10):
        ours, theirs = peers.numba_dop853(p, save, t_end, rtol), peers.scipy_dop853(p, save, t_end, rtol)
        e_ours, e_theirs = _error(ours.force, ref), _error(theirs.force, ref)
        assert e_theirs / 10 < e_ours < 10 * e_theirs, (rtol, e_ours, e_theirs)
        assert abs(ours.steps - theirs.steps) <= 0.2 * theirs.steps


def test_numba_dop853_on_a_smooth_problem():
    # precompressed chain, a small kick: no contact opens, DOP853 keeps its order 8
    chain = Chain([Bead(**STEEL)] * 30, wall=Wall(), gravity=0, top_force=2.38)
    p = ChainProblem.from_chain(chain)
    p.v0[2] = 0.01
    save = record_contacts(chain, 20, sample_interval=1e-6)
    ref = solve(p, 0.3e-3, save=save, dt=contact_time_scale(p) / 400).forces["c20"]
    run = peers.numba_dop853(p, save, 0.3e-3, 1e-10)
    assert _error(run.force, ref, scale=np.max(np.abs(ref - ref[0]))) < 1e-7  # of the dynamic part


def test_a_peer_records_one_contact_force():
    chain = steel_sonic_vacuum(n=20)
    p = ChainProblem.from_chain(chain)
    with pytest.raises(RigError, match="one contact force"):
        peers.numba_dop853(p, record_contacts(chain, 5, 10), 1e-5, 1e-6)


@needs_lammps
@pytest.mark.parametrize("slot", [1, 8])
def test_lammps_force_law_is_the_problems(slot):
    # sonic vacuum (no load, d0 = 0): the body above slot pressed down by d, its contact above
    # opened by as much: +-A d^(3/2) on the two bodies of the slot (1: the striker on bead 0)
    p = ChainProblem.from_chain(steel_sonic_vacuum(n=20))
    d = 2e-7
    u = np.zeros(p.n_bodies)
    u[slot - 1] = d
    F = lammps.lammps_forces(p, u)
    assert F[slot - 1] == pytest.approx(-p.A[slot] * d**1.5, rel=1e-8)
    assert F[slot] == pytest.approx(p.A[slot] * d**1.5, rel=1e-8)


@needs_lammps
@pytest.mark.parametrize("build", [steel_sonic_vacuum, ptfe_rig], ids=["sonic-vacuum", "ptfe"])
def test_lammps_computes_the_chains_forces(build):
    # any displacement: the project's net force f[i] - f[i+1] (contacts, striker, wall, gravity, top force)
    p = ChainProblem.from_chain(build(n=20))
    moving = p.invm > 0
    u = np.random.default_rng(7).normal(0.0, 1e-7, p.n_bodies) * moving
    F = lammps.lammps_forces(p, u)
    f = np.zeros(p.n_bodies + 1)
    hertz_forces(u, p.A, p.d0, p.load, f)
    f[-1] = -p.load[-1]
    net = (f[:-1] - f[1:])[moving]
    assert np.max(np.abs(F[moving] - net)) < 1e-8 * np.max(np.abs(net))


@needs_lammps
def test_lammps_converges_at_order_2(case):
    p, save, t_end, ref = case["sonic-vacuum"]
    tau = contact_time_scale(p)
    coarse, fine = (lammps.lammps_hertz(p, save, t_end, tau / r) for r in (20, 100))
    e_coarse, e_fine = _error(coarse.force, ref), _error(fine.force, ref)
    assert e_fine < 1e-4 and 15 < e_coarse / e_fine < 30, (e_coarse, e_fine)  # (100/20)^2 = 25 at dt' = dt
    assert fine.steps > 4 * coarse.steps and fine.cpu_s > 0
