"""Fitted convergence slopes against each method's declared order.

Smooth case: a precompressed chain perturbed so weakly that no contact opens, where the
compositions keep their classical order. Non-smooth case: a sonic-vacuum chain whose
contacts open behind the pulse (d^(3/2) has an infinite second derivative at d = 0),
where each method must still reach its declared ``contact_order``.
"""
import numpy as np
import pytest
from chains import STEEL, record_contacts, steel_sonic_vacuum

from rig import METHODS, Bead, Chain, ChainProblem, Wall, solve
from rig.solver.stepsize import contact_time_scale

SLOPE_TOL = 0.25  # the least-squares slope over a factor 8 in dt


def _slope(p, save, t_end, method, ratios):
    tau = contact_time_scale(p)
    ref = solve(p, t_end, save=save, method="srkn6b", dt=tau / 1024).forces["c20"]
    scale = np.abs(ref - ref[0]).max()
    errs = [np.abs(solve(p, t_end, save=save, method=method, dt=tau / r).forces["c20"] - ref).max() / scale
            for r in ratios]
    return -np.polyfit(np.log(ratios), np.log(errs), 1)[0], errs


def _smooth_problem():
    chain = Chain([Bead(**STEEL)] * 30, wall=Wall(), gravity=0, top_force=2.38)
    p = ChainProblem.from_chain(chain)
    p.v0[2] = 0.01  # a small kick to bead 2: the contacts never open
    return p, record_contacts(chain, 20)


@pytest.mark.parametrize("name,ratios", [("verlet", [4, 8, 16, 32]), ("srkn6b", [2, 4, 8, 16])])
def test_classical_order_on_smooth_chain(name, ratios):
    slope, errs = _slope(*_smooth_problem(), 2e-4, name, ratios)
    assert abs(slope - METHODS[name].order) < SLOPE_TOL, (slope, errs)


@pytest.mark.parametrize("name,ratios", [("verlet", [8, 16, 32, 64]), ("srkn6b", [4, 8, 16, 32, 64])])
def test_declared_contact_order_with_opening_contacts(name, ratios):
    chain = steel_sonic_vacuum(n=30)
    slope, errs = _slope(ChainProblem.from_chain(chain), record_contacts(chain, 20), 2.2e-4, name, ratios)
    assert slope > METHODS[name].contact_order - SLOPE_TOL, (slope, errs)
