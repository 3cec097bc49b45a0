"""The power-law dashpot gamma |d'|^alpha sgn d' (rig.model.laws.powerlaw_dashpot): alpha = 1
is the linear dashpot bit for bit; its flow (rig/solver/kernels/dissipation.py) is second
order while the closing rate is away from 0 and, for alpha < 1, stops a contact's relative
motion without reversing it; a strong sub-linear dashpot stays stable and its energy
balance closes. (Order, energy balance and batched shots at alpha 0.5 and 1.5:
tests/solver/test_models.py.)"""
import numpy as np
import pytest
from chains import PTFE, record_contacts
from test_models import _forces, _slope, ptfe_chain

from rig import Bead, Chain, ChainProblem, Wall
from rig.model.contact import KUWABARA_KONO
from rig.solver.ensemble import solve_ensemble
from rig.solver.kernels.dissipation import dissipate
from rig.solver.problem import CONTACT_ROWS, STATE_ROWS
from rig.solver.stepsize import contact_time_scale, stepping_at

M, R0 = 1e-4, 0.3  # each bead's mass (kg), the pair's closing rate (m/s)


def pair_flow(alpha, gamma, t, substeps):
    """Two free beads of mass M in contact, closing at R0: the contacts' viscous flow over t
    seconds in ``substeps`` substeps. (closing rate after (m/s), energy it took (J), momentum
    after (kg m/s))."""
    u, v = np.zeros((2, 1)), np.array([[R0], [0.0]])
    mass = np.full((2, 1), M)
    A, d0 = np.array([[0.0], [1e3]]), np.array([[0.0], [1e-5]])
    con = np.zeros((len(CONTACT_ROWS), 2, 1))
    con[0], con[3] = 1.5, 1.0
    con[2, 1, 0], con[3, 1, 0] = gamma, alpha
    hold = np.zeros((2, 2, 1))
    hold[0] = 1.0
    lost, j_wall, j_holder = np.zeros(1), np.zeros(1), np.zeros(1)
    dissipate(u, v, mass, 1.0 / mass, A, d0, con, KUWABARA_KONO, np.zeros((len(STATE_ROWS), 2, 1)), hold,
              1e-3, True, False, substeps / t, t, 0,
              np.zeros((5, 3, 1)), lost, j_wall, j_holder)
    return v[0, 0] - v[1, 0], lost[0], M * (v[0, 0] + v[1, 0])


def exact_rate(alpha, gamma, t):
    """The lone pair's closing rate: r' = -(2/M) gamma r^alpha, r = 0 from the stop on (alpha < 1)."""
    return max(R0 ** (1 - alpha) - (1 - alpha) * (2 / M) * gamma * t, 0.0) ** (1 / (1 - alpha))


def stop_time(alpha, gamma):
    return R0 ** (1 - alpha) / ((1 - alpha) * (2 / M) * gamma)


@pytest.mark.parametrize("alpha", [0.3, 0.5, 0.8])
def test_pair_flow_is_second_order_before_the_stop(alpha):
    t = 0.5 * stop_time(alpha, 1.0)
    errs = [abs(pair_flow(alpha, 1.0, t, n)[0] - exact_rate(alpha, 1.0, t)) for n in (16, 64)]
    assert errs[0] / errs[1] == pytest.approx(16.0, rel=0.25), errs


@pytest.mark.parametrize("alpha", [0.3, 0.5, 0.8])
def test_pair_flow_stops_without_reversing_and_books_the_energy(alpha):
    """Past the stop the closing rate falls to rounding, never below 0 (an explicit step of the
    unbounded coefficient gamma r^(alpha-1) overshoots and chatters instead); the energy the flow
    took is the kinetic energy the pair lost; momentum is kept."""
    for n in (4, 16, 64):
        r, lost, p = pair_flow(alpha, 1.0, 2.0 * stop_time(alpha, 1.0), n)
        assert r >= 0.0
        assert lost == pytest.approx(0.25 * M * (R0**2 - r**2), rel=1e-12)
        assert p == pytest.approx(M * R0, rel=1e-14)
    assert r < 1e-8 * R0


def test_alpha_one_is_the_linear_dashpot_bit_for_bit():
    linear = ptfe_chain(contact_law="dashpot", contact_damping=2.0)
    power = ptfe_chain(contact_law="powerlaw-dashpot", dashpot_gamma=2.0, dashpot_exponent=1.0)
    tau = contact_time_scale(ChainProblem.from_chain(linear))
    a, b = _forces(linear, 2e-4, tau / 8), _forces(power, 2e-4, tau / 8)
    assert all(np.array_equal(a.forces[k], b.forces[k]) for k in a.forces)
    assert a.stats.dissipated_energy_J == b.stats.dissipated_energy_J > 0
    p = ChainProblem.from_chain(power)
    batch = solve_ensemble([p, p], 2e-4, save=record_contacts(power, 5, 12, 20), dt=stepping_at(p, tau / 8))
    assert all(np.array_equal(batch.forces[k][1], a.forces[k]) for k in a.forces)


@pytest.mark.parametrize("alpha,gamma", [(0.2, 10.0), (0.5, 30.0), (3.0, 1e3)])
def test_strong_dashpots_stay_stable_and_never_pull(alpha, gamma):
    """Far stronger than the linear dashpot's 2 kg/s: the run ends ok, the energy balance
    closes, the contacts' forces are never negative, and the dashpot took a share of the
    striker's energy."""
    chain = ptfe_chain(contact_law="powerlaw-dashpot", dashpot_gamma=gamma, dashpot_exponent=alpha)
    tau = contact_time_scale(ChainProblem.from_chain(chain))
    sol = _forces(chain, 3e-4, tau / 8)
    assert sol.status == 0 and sol.stats.energy_error < 1e-5
    assert min(f.min() for f in sol.forces.values()) >= 0.0
    kinetic = 0.5 * chain.striker.mass * chain.striker.velocity ** 2
    assert 0.3 * kinetic < sol.stats.dissipated_energy_J < kinetic


def test_sub_linear_dashpot_order_on_a_smooth_chain():
    """Precompressed and weakly kicked: a weak sub-linear dashpot keeps the split's second
    order; one strong enough to hold contacts at rest (a rate stuck at 0, where its force is
    not smooth) still converges, at below first order."""
    def slope(gamma, ratios):
        chain = Chain([Bead(**PTFE)] * 20, wall=Wall(), gravity=0, top_force=2.38, contact_law="powerlaw-dashpot",
                      dashpot_gamma=gamma, dashpot_exponent=0.5)
        return _slope(chain, 2e-4, ratios, contacts=(10, 20), kick=2)

    weak, errs = slope(0.01, [4, 8, 16])
    assert weak > 2 - 0.25, (weak, errs)
    strong, errs = slope(1.1, [8, 16, 32])
    assert strong > 0.5 and errs[-1] < errs[0] / 2, (strong, errs)
