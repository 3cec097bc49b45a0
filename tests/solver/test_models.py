"""The real-chain models (scene options, off by default): a power-law contact A d^n,
viscous contacts (Kuwabara-Kono, dashpot, power-law dashpot), the holder's drag and friction, and a compliant
wall (a plate on a rod). Each: the default is today's Hertz chain bit for bit, zero
damping is the conservative kernel, the order of convergence, the energy balance with the
dissipated energy, and batched shots equal single shots."""
import math

import numpy as np
import pytest
from chains import PTFE, STEEL, record_contacts, steel_sonic_vacuum

from rig import Bead, Chain, ChainProblem, Striker, Wall, solve
from rig.errors import RigError
from rig.solver.ensemble import solve_ensemble
from rig.solver.kernels.dissipation import holder_flow
from rig.solver.stepsize import contact_time_scale, stepping_at

SLOPE_TOL = 0.25  # least-squares slope over a factor 4-8 in dt, as in test_convergence

MODELS = {
    "power 1.75": dict(contact_exponent=1.75),
    "power 1.25": dict(contact_exponent=1.25),
    "kuwabara-kono": dict(contact_law="kuwabara-kono", damping_time=2e-6),
    "dashpot": dict(contact_law="dashpot", contact_damping=2.0),
    # about the dashpot's 0.6 N at a closing rate of 0.3 m/s
    "powerlaw-dashpot 0.5": dict(contact_law="powerlaw-dashpot", dashpot_gamma=1.1, dashpot_exponent=0.5),
    "powerlaw-dashpot 1.5": dict(contact_law="powerlaw-dashpot", dashpot_gamma=3.6, dashpot_exponent=1.5),
    "drag": dict(drag=0.05),
    "friction": dict(friction=2e-3),
    "compliant wall": dict(wall=Wall(plate_mass="2 g", rod_stiffness="1e8 N/m")),
}
DISSIPATIVE = ("kuwabara-kono", "dashpot", "powerlaw-dashpot 0.5", "powerlaw-dashpot 1.5", "drag", "friction")


def ptfe_chain(n=20, **kw):
    """A vertical PTFE chain on a wall, struck at 0.89 m/s (the published shot, shorter)."""
    wall = kw.pop("wall", Wall())
    return Chain([Bead(**PTFE)] * n, striker=Striker("alumina", "0.47 g", "0.89 m/s"), wall=wall, **kw)


def _forces(chain, t_end, dt, contacts=(5, 12, 20)):
    p = ChainProblem.from_chain(chain)
    return solve(p, t_end, save=record_contacts(chain, *contacts), dt=stepping_at(p, dt), estimate=False)


def _max_rel(a, b):
    scale = max(np.abs(b[k]).max() for k in b)
    return max(np.abs(a[k] - b[k]).max() for k in b) / scale


def test_defaults_are_todays_hertz_bit_for_bit():
    """n = 3/2 and every model at zero take the Hertz kernel: same forces, same bits."""
    chain = ptfe_chain()
    tau = contact_time_scale(ChainProblem.from_chain(chain))
    ref = _forces(chain, 2e-4, tau / 8).forces
    for kw in (dict(contact_exponent=1.5), dict(contact_exponent=1.5, reference_force=7.0),
               dict(drag=0.0, friction=0.0), dict(contact_law="hertz", reference_force=3.0)):
        got = _forces(ptfe_chain(**kw), 2e-4, tau / 8).forces
        assert all(np.array_equal(got[k], ref[k]) for k in ref), kw


def test_power_law_at_three_halves_is_hertz_to_rounding():
    """The power-law kernel (law code POWER) at n = 3/2 computes A d^1.5 by pow, Hertz by
    d sqrt(d): with the same stepping (no multirate head, which takes Hertz slots only),
    the same forces to a few ulps of the peak per step."""
    chain = ptfe_chain()
    p = ChainProblem.from_chain(chain)
    p_pow = ChainProblem.from_chain(ptfe_chain(contact_exponent=1.5 + 1e-15))
    assert p_pow.law != p.law
    dt = contact_time_scale(p) / 8
    save = record_contacts(chain, 5, 12, 20)
    a = solve(p, 2e-4, save=save, dt=stepping_at(p, dt, head=0), estimate=False).forces
    b = solve(p_pow, 2e-4, save=save, dt=stepping_at(p_pow, dt, head=0), estimate=False).forces
    assert _max_rel(b, a) < 1e-11


def test_power_law_constant_matches_hertz_at_the_reference_force():
    """F = A_n d^n is matched to Hertz at the reference force: equal force and overlap there."""
    from rig.model.contact import hertz_force, power_law_constant, static_overlaps
    A, F = 5.0e9, 2.5
    for n in (1.0, 1.25, 1.75, 2.5):
        An = power_law_constant(A, n, F)
        d = static_overlaps(A, F)
        assert math.isclose(hertz_force(An, d, n), F, rel_tol=1e-13)
        assert math.isclose(static_overlaps(An, F, n), d, rel_tol=1e-13)


@pytest.mark.parametrize("name", ["dashpot", "kuwabara-kono", "drag", "friction"])
def test_vanishing_damping_tends_to_the_conservative_chain_linearly(name):
    """The dissipative split at damping c differs from the conservative run by O(c): halving
    c halves the difference (ratio 2 within 10%)."""
    kw = dict(MODELS[name])
    key = next(k for k in kw if k not in ("contact_law",))
    chain = ptfe_chain()
    tau = contact_time_scale(ChainProblem.from_chain(chain))
    ref = _forces(chain, 2e-4, tau / 8).forces
    diffs = []
    for scale in (1e-3, 5e-4):
        kw[key] = MODELS[name][key] * scale
        diffs.append(_max_rel(_forces(ptfe_chain(**kw), 2e-4, tau / 8).forces, ref))
    assert 0 < diffs[1] < diffs[0]
    assert diffs[0] / diffs[1] == pytest.approx(2.0, rel=0.1), diffs


def _slope(chain, t_end, ratios, contacts=(5, 12, 20), kick=None):
    p = ChainProblem.from_chain(chain)
    if kick is not None:
        p.v0[kick] = 0.01  # a small kick: the contacts never open
    tau = contact_time_scale(p)
    save = record_contacts(chain, *contacts)
    def run(r):
        return solve(p, t_end, save=save, dt=stepping_at(p, tau / r), estimate=False).forces
    ref = run(128)
    errs = [_max_rel(run(r), ref) for r in ratios]
    return -np.polyfit(np.log(ratios), np.log(errs), 1)[0], errs


@pytest.mark.parametrize("name,order", [("power 1.75", 4), ("power 1.25", 4), ("compliant wall", 4),
                                        ("kuwabara-kono", 2), ("dashpot", 2), ("powerlaw-dashpot 1.5", 2),
                                        ("drag", 2), ("friction", 2)])
def test_order_on_a_smooth_chain(name, order):
    """Precompressed and weakly kicked, no contact opens: the elastic models keep srkn6b's
    classical order 4; the dissipative ones are Strang-split, second order (a sub-linear
    dashpot, alpha < 1, is not smooth where a closing rate passes 0:
    tests/solver/test_powerlaw_dashpot.py)."""
    kw = dict(MODELS[name], gravity=0, top_force=2.38)
    slope, errs = _slope(Chain([Bead(**PTFE)] * 20, wall=kw.pop("wall", Wall()), **kw), 2e-4, [2, 4, 8],
                         contacts=(10, 20), kick=2)
    assert slope > order - SLOPE_TOL, (slope, errs)


@pytest.mark.parametrize("name,order", [("power 1.75", 2.75), ("power 1.25", 2.25), ("compliant wall", 2.5),
                                        ("kuwabara-kono", 1), ("dashpot", 1), ("powerlaw-dashpot 0.5", 1),
                                        ("powerlaw-dashpot 1.5", 1), ("drag", 2), ("friction", 2)])
def test_order_with_opening_contacts(name, order):
    """Struck, the contacts open behind the pulse: an elastic law A d^n limits srkn6b to
    n + 1 (its declared contact order 2.5 for Hertz); a viscous contact's force has a kink
    where it is clipped (it never pulls) and the dashpot's a jump where it closes, events
    that leave first order."""
    slope, errs = _slope(ptfe_chain(**MODELS[name]), 2.5e-4, [4, 8, 16])
    assert slope > order - SLOPE_TOL, (slope, errs)


@pytest.mark.parametrize("name", list(MODELS))
def test_energy_balance_closes_with_the_dissipated_energy(name):
    """E(t) + dissipated = E(0) to the method's error, which falls with dt; a dissipative
    model reports the energy it took (a positive fraction of the striker's), the others 0."""
    chain = ptfe_chain(**MODELS[name])
    tau = contact_time_scale(ChainProblem.from_chain(chain))
    coarse, fine = (_forces(chain, 3e-4, tau / r).stats for r in (4, 16))
    assert fine.energy_error < coarse.energy_error or fine.energy_error < 1e-12
    assert fine.energy_error < 1e-5
    kinetic = 0.5 * chain.striker.mass * chain.striker.velocity ** 2
    if name in DISSIPATIVE:
        assert 1e-4 * kinetic < fine.dissipated_energy_J < kinetic
        assert fine.dissipated_energy_J == pytest.approx(coarse.dissipated_energy_J, rel=0.05)
    else:
        assert fine.dissipated_energy_J == 0.0


@pytest.mark.parametrize("name", list(MODELS))
def test_batched_shots_equal_single_shots(name):
    chain = ptfe_chain(**MODELS[name])
    p = ChainProblem.from_chain(chain)
    step = stepping_at(p, contact_time_scale(p) / 8)
    save = record_contacts(chain, 5, 12, 20)
    single = solve(p, 2e-4, save=save, dt=step, estimate=False)
    batch = solve_ensemble([p, p, p], 2e-4, save=save, dt=step)
    for k in single.forces:
        assert np.array_equal(batch.forces[k][1], single.forces[k]), k
    assert batch.stats(2).dissipated_energy_J == single.stats.dissipated_energy_J


def test_stiff_rod_tends_to_the_rigid_wall():
    """A plate on a rod of stiffness k moves by F/k: the wall's force tends to the rigid
    wall's as 1/k (ten times stiffer, about ten times closer)."""
    chain = steel_sonic_vacuum(n=10, wall=True)
    tau = contact_time_scale(ChainProblem.from_chain(chain))
    rigid = _forces(chain, 1.2e-4, tau / 16, (10,)).forces
    diffs = []
    for k in (1e9, 1e10):
        soft = Chain([Bead(**STEEL)] * 10, striker=chain.striker, wall=Wall(plate_mass="5 g", rod_stiffness=k),
                     gravity=0)
        diffs.append(_max_rel(_forces(soft, 1.2e-4, tau / 16, (10,)).forces, rigid))
    assert diffs[1] < diffs[0] / 4, diffs


def test_holder_flow_exact_limits():
    """Drag alone: v e^(-gamma t). Friction at |v| >> slip: |v| falls by a t (sliding);
    near rest, it decays and never changes sign."""
    half_decay = math.exp(-0.5 * 200.0 * 1e-3)  # gamma = 200 /s over t = 1 ms
    assert holder_flow(0.3, half_decay, 0.0, 1e-3, 1e-3) == pytest.approx(0.3 * math.exp(-0.2), rel=1e-14)
    assert holder_flow(0.3, 1.0, 50.0, 1e-4, 1e-3) == pytest.approx(0.25, rel=1e-12)
    assert holder_flow(-0.3, 1.0, 50.0, 1e-4, 1e-3) == pytest.approx(-0.25, rel=1e-12)
    v = holder_flow(1e-5, 1.0, 50.0, 1e-4, 1e-3)
    assert 0 < v < 1e-5


@pytest.mark.parametrize("kw,field", [
    (dict(contact_exponent=0.5), "chain.contact_exponent"),
    (dict(contact_law="dashpot"), "chain.contact_damping"),
    (dict(contact_law="kuwabara-kono", damping_time=1e-6, contact_damping=1.0), "chain.contact_damping"),
    (dict(contact_law="viscous"), "chain.contact_law"),
    (dict(drag=-1.0), "holder.drag"),
    (dict(friction=-1.0), "holder.friction"),
    (dict(slip_speed=0.0), "holder.slip_speed"),
    (dict(reference_force=0.0), "chain.reference_force"),
])
def test_bad_model_settings_name_the_field(kw, field):
    with pytest.raises(RigError, match=field.replace(".", r"\.")):
        ptfe_chain(**kw)


def test_a_plate_without_a_rod_is_refused():
    with pytest.raises(RigError, match=r"wall\.plate_mass.*both plate_mass and rod_stiffness"):
        Wall(plate_mass="2 g")
