"""Numerically hard shots: each must give finite results and close its conservation."""
import importlib

import numpy as np
import pytest
from chains import PTFE, STEEL, ptfe_rig, record_contacts, steel_sonic_vacuum

from rig import Bead, Chain, ChainProblem, RigError, SaveAt, Striker, Wall, solve
from rig.solver.methods import METHODS
from rig.solver.stepsize import stability_limit


def _finite(sol):
    assert all(np.all(np.isfinite(f)) for f in sol.forces.values())
    assert np.all(np.isfinite(sol.final_v))


def test_sonic_vacuum_gaps_and_striker_rebound():
    # a striker lighter than the beads bounces back; gaps open behind the pulse
    chain = Chain([Bead(**STEEL)] * 40, striker=Striker("alumina", "0.2 g", "1 m/s"), gravity=0)
    p, save = ChainProblem.from_chain(chain), record_contacts(chain, 0, 30)
    sol = solve(p, 0.4e-3, save=save)
    _finite(sol)
    assert sol.final_v[0] < -0.1  # rebound
    d = p.d0[1:] + sol.final_u[:-1] - sol.final_u[1:]
    assert np.sum(d < 0) > 10  # many open contacts
    assert sol.forces["c0"][-1] == 0.0
    assert sol.stats.energy_error < 1e-4
    assert sol.stats.momentum_error < 1e-10


def test_wall_reflection():
    chain = steel_sonic_vacuum(n=20, wall=True)
    p, save = ChainProblem.from_chain(chain), SaveAt({"wall": chain.wall_probe(), "c5": chain.contact_probe(5)})
    sol = solve(p, 0.6e-3, save=save)  # the pulse reaches the wall and comes back past bead 5
    _finite(sol)
    peaks = sol.forces["c5"]
    assert sol.forces["wall"].max() > 1.5 * peaks[: len(peaks) // 3].max()  # reflection doubles
    assert sol.stats.energy_error < 1e-4
    assert sol.stats.momentum_error < 1e-10
    # all the striker's momentum, and more, went into the wall
    assert sol.stats.wall_impulse_Ns > chain.striker.mass * chain.striker.velocity


def test_ptfe_steel_interface():
    chain = Chain([Bead(**PTFE)] * 20 + [Bead(**STEEL)] * 20,
                  striker=Striker("alumina", "0.47 g", "0.89 m/s"), wall=Wall(), gravity=9.80665)
    A = chain.contact_constants()
    assert A[25] / A[5] > 100  # stiffness ratio across the interface
    sol = solve(chain, 1.2e-3, save=record_contacts(chain, 10, 30, 40))
    _finite(sol)
    assert sol.forces["c30"].max() > 0.1 * sol.forces["c10"].max()  # transmitted
    assert sol.stats.energy_error < 1e-4
    assert sol.stats.momentum_error < 1e-10


def test_ten_thousand_beads():
    chain = Chain([Bead(**STEEL)] * 10_000, striker=Striker("steel316", "0.4501 g", "0.44 m/s"),
                  wall=Wall())
    assert chain.static_forces()[-1] > 44.0  # 10,000 steel beads weigh 44 N on the wall
    sol = solve(chain, 0.3e-3, save=record_contacts(chain, 20, 9_000))
    _finite(sol)
    assert sol.forces["c20"].max() > 10.0
    assert np.ptp(sol.forces["c9000"]) < 1e-9 * sol.forces["c9000"][0]  # far end at rest
    assert np.max(np.abs(sol.final_v[5000:])) < 1e-9
    assert sol.stats.energy_error < 1e-4
    assert sol.stats.momentum_error < 1e-10


def test_tiny_amplitude_on_precompression():
    # 0.1 N dynamic force on 2.38 N: a nearly linear wave
    chain = ptfe_rig(n=52, top_force=2.38, velocity="0.0185 m/s")
    p, save = ChainProblem.from_chain(chain), SaveAt({"g20": chain.gauge_probe(20)})
    sol = solve(p, 0.6e-3, save=save)
    _finite(sol)
    g = sol.forces["g20"]
    dynamic = g.max() - g[0]
    assert 0.05 < dynamic < 0.2
    assert sol.stats.energy_error < 1e-4
    assert sol.stats.momentum_error < 1e-10


def test_hard_impact():
    chain = ptfe_rig(n=52, velocity="5 m/s")
    sol = solve(chain,
                1.0e-3, save=SaveAt({"g20": chain.gauge_probe(20), "wall": chain.wall_probe()}))
    _finite(sol)
    assert sol.forces["g20"].max() > 30.0
    assert sol.stats.energy_error < 1e-4
    assert sol.stats.momentum_error < 1e-10


@pytest.mark.parametrize("name", ["verlet", "srkn6b"])
def test_step_beyond_stability_is_refused(name):
    chain = ptfe_rig(n=10)
    p = ChainProblem.from_chain(chain)
    limit = stability_limit(p, METHODS[name])
    with pytest.raises(RigError, match="stability limit"):
        solve(p, 1e-4, method=name, dt=1.5 * limit)
    solve(p, 1e-4, method=name, dt=0.9 * limit)  # just inside runs


def test_blow_up_is_reported_not_returned(monkeypatch):
    # a dt far past the linear limit with the up-front check switched off: the kernel's
    # own guard stops, and the solve raises a clear error rather than returning garbage
    chain = ptfe_rig(n=10)
    p = ChainProblem.from_chain(chain)
    dt = 20 * stability_limit(p, METHODS["verlet"])
    monkeypatch.setattr(importlib.import_module("rig.solver.solve"), "stability_limit", lambda *a: np.inf)
    with pytest.raises(RigError, match="unstable"):
        solve(p, 1e-3, method="verlet", dt=dt)
