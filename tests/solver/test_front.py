"""The front: a step integrates only the bodies the pulse has reached, and that changes no
bit of anything recorded (rig/solver/kernels/integrators.py)."""
import numpy as np
import pytest
from chains import ptfe_rig, record_contacts, steel_sonic_vacuum

from rig import Bead, Chain, ChainProblem, ForceSchedule, SaveAt, Striker, Wall
from rig.solver.ensemble import solve_ensemble
from rig.solver.kernels.forces import elastic_forces
from rig.solver.kernels.integrators import rest_from
from rig.solver.methods import method
from rig.solver.problem import CONTACT_ROWS
from rig.solver.run import integrate_at
from rig.solver.stepsize import Stepping, contact_time_scale, stepping_at

STEEL = dict(material="steel316", diameter="4.76 mm", mass="0.4501 g")


def _cases():
    """(label, chain, t_end s): records that end before the pulse fills the chain."""
    steel = Bead(**STEEL)
    return [
        ("sonic vacuum", steel_sonic_vacuum(n=80), 0.5e-3),
        ("precompressed, wall", Chain([steel] * 80, striker=Striker("steel316", "0.4501 g", "0.44 m/s"),
                                      wall=Wall(), gravity=0, top_force=2.38), 0.4e-3),
        ("gravity, striker in flight", ptfe_rig(n=60, top_force=0.0), 0.6e-3),
        ("magnet schedule", ptfe_rig(n=60, top_force=ForceSchedule((0, 2e-4), (2.38, 3.0))), 0.6e-3),
        ("compliant wall (a linear rod)",
         Chain([steel] * 60, striker=Striker("steel316", "0.4501 g", "0.44 m/s"),
               wall=Wall(plate_mass=0.02, rod_stiffness=2e8), gravity=9.80665), 0.3e-3),
    ]


def _bits(a):
    return np.ascontiguousarray(a, dtype=np.float64).view(np.uint64)


@pytest.mark.parametrize("label,chain,t_end", _cases(), ids=[c[0] for c in _cases()])
@pytest.mark.parametrize("head", [False, True])
def test_the_front_changes_no_bit(label, chain, t_end, head):
    p = ChainProblem.from_chain(chain)
    dt = contact_time_scale(p) / 6
    stepping = stepping_at(p, dt) if head else Stepping(dt)
    n = chain.n_beads
    save = SaveAt({f"c{k}": chain.contact_probe(k) for k in (2, n // 3, n - 1)} | {"wall": chain.wall_probe()}
                  if chain.wall is not None else {f"c{k}": chain.contact_probe(k) for k in (2, n // 3, n - 1)},
                  sample_interval=1e-6, frame_interval=2e-5)
    m = method("srkn6b")
    fast = integrate_at(p, t_end, save, m, stepping)
    whole = integrate_at(p, t_end, save, m, stepping, front=False)
    assert whole.stats.bodies_stepped == p.n_bodies
    assert fast.stats.bodies_stepped < 0.9 * p.n_bodies, "the front took (nearly) every body"
    for name in save.names:
        assert np.array_equal(_bits(fast.forces[name]), _bits(whole.forces[name])), name
    assert np.array_equal(_bits(fast.frames), _bits(whole.frames))
    assert np.array_equal(_bits(fast.final_u), _bits(whole.final_u))
    assert np.array_equal(_bits(fast.final_v), _bits(whole.final_v))
    for key in ("energy_error", "momentum_error", "wall_impulse_Ns"):
        assert getattr(fast.stats, key) == getattr(whole.stats, key), key


def test_a_chain_at_rest_is_at_rest_bit_for_bit():
    """balance_at_rest: every bead resting on the chain has forces at rest that cancel
    exactly, so the front can leave it; beads of a chain under gravity below a striker in
    flight too (their slots all carry its weight)."""
    for chain in (Chain([Bead(**STEEL)] * 200, striker=Striker("steel316", "0.4501 g", "0.44 m/s"), wall=Wall(),
                        gravity=0, top_force=2.38), ptfe_rig(n=52, top_force=2.38)):
        p = ChainProblem.from_chain(chain)
        f = np.zeros(p.n_bodies + 1)
        f[-1] = -p.load[-1]
        con = np.stack([getattr(p, k) for k in CONTACT_ROWS])
        elastic_forces(p.u0.copy(), p.A, p.d0, p.load, f, p.law, con, p.memory()[:, :, None])
        rest = (f[:-1] == f[1:]) | (p.invm == 0)
        assert rest[2:].all(), np.flatnonzero(~rest)
        assert rest_from(p.v0, p.invm, f, 1) <= 2  # the striker (and the magnetic bead it strikes) only
        # the loads moved by rounding only
        plain = np.concatenate(([0.0], np.cumsum(p.mass * p.bias)))
        assert np.allclose(p.load, plain, rtol=1e-14, atol=0)


def test_a_batch_keeps_its_front_and_the_single_shots_bits():
    chains = [steel_sonic_vacuum(n=80, velocity=f"{0.3 + 0.05 * k} m/s") for k in range(5)]
    probs = [ChainProblem.from_chain(c) for c in chains]
    save = record_contacts(chains[0], 3, 30)
    dt = Stepping(contact_time_scale(probs[-1]) / 6)
    ens = solve_ensemble(probs, 0.5e-3, save=save, dt=dt, width=4)
    for k, p in enumerate(probs):
        whole = integrate_at(p, 0.5e-3, save, method("srkn6b"), dt, front=False)
        for name in save.names:
            assert np.array_equal(_bits(ens.forces[name][k]), _bits(whole.forces[name])), name


def test_dissipation_takes_every_body():
    chain = steel_sonic_vacuum(n=40)
    p = ChainProblem.from_chain(Chain(chain.beads, striker=chain.striker, gravity=0, drag=5e-3))
    sol = integrate_at(p, 0.2e-3, SaveAt(), method("srkn6b"), Stepping(contact_time_scale(p) / 6))
    assert sol.stats.bodies_stepped == p.n_bodies
