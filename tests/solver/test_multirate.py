"""The multirate head: a stiff striker contact substepped, the chain at its own step."""
import numpy as np
import pytest
from conftest import ptfe_rig, record_contacts, steel_sonic_vacuum

from rig import ChainProblem, solve
from rig.solver.methods import method
from rig.solver.stepsize import (
    HEAD_SUBSTEP,
    Stepping,
    accuracy_step,
    contact_time_scale,
    default_step,
    fast_head,
    stability_limit,
)

SRKN = method("srkn6b")


def test_the_alumina_striker_on_the_steel_bead_is_the_head():
    chain = ptfe_rig(n=30)
    p = ChainProblem.from_chain(chain)
    assert fast_head(p) == 1
    st = default_step(p, SRKN, 1e-4)
    single = min(accuracy_step(p, SRKN, 1e-4), 0.5 * stability_limit(p, SRKN))  # the single-rate rule
    assert st.head == 1 and st.dt > 3 * single  # the PTFE contacts allow a step > 3x the striker's
    assert st.inner_dt == HEAD_SUBSTEP * single
    uniform = steel_sonic_vacuum(n=40)
    assert fast_head(ChainProblem.from_chain(uniform)) == 0  # nothing stiffer: single rate


def test_multirate_default_meets_the_accuracy_on_the_first_crossing():
    # force error of every recorded contact while the pulse crosses the chain, against a
    # single-rate solve at tau/300; the default target is 1e-4
    chain = ptfe_rig(n=30)
    p, save = ChainProblem.from_chain(chain), record_contacts(chain, 5, 15, 25)
    ref = solve(p, 0.45e-3, dt=contact_time_scale(p) / 300, save=save)
    for acc in (1e-4, 1e-5):
        sol = solve(p, 0.45e-3, accuracy=acc, save=save)
        assert sol.stats.dt_s > 6 * default_step(p, SRKN, acc).inner_dt
        err = max(np.max(np.abs(sol.forces[k] - ref.forces[k])) / np.max(np.abs(ref.forces[k])) for k in ref.forces)
        assert err < acc, (acc, err)
        assert sol.stats.energy_error < acc
        assert sol.stats.momentum_error < 1e-10


def test_head_substeps_converge_to_the_exact_head_flow():
    # the outer step fixed, the head's substep refined: the error falls to the outer step's own
    chain = ptfe_rig(n=30)
    p, save = ChainProblem.from_chain(chain), record_contacts(chain, 10)
    ref = solve(p, 0.3e-3, dt=contact_time_scale(p) / 300, save=save)
    errs = []
    for inner in (1e-6, 2.5e-7, 6.25e-8):
        sol = solve(p, 0.3e-3, dt=Stepping(2e-6, 1, inner), save=save)
        errs.append(np.max(np.abs(sol.forces["c10"] - ref.forces["c10"])) / np.max(np.abs(ref.forces["c10"])))
    assert errs[0] > errs[1] > errs[2]
    assert errs[2] < 1e-5


def test_a_free_head_flies_exactly_and_still_lands_on_time():
    # a striker 0.1 mm above the top bead: until it lands, its flow under gravity is taken
    # in closed form (its contact is provably open); it must be the ballistic parabola, and
    # the impact, once it comes, must match a head substepped everywhere
    from rig import Striker
    from rig.model.chain import Chain

    base = ptfe_rig(n=30)
    g = base.gravity
    chain = Chain(base.beads, striker=Striker("alumina", "0.47 g", "0.89 m/s", gap="0.1 mm"), wall=base.wall,
                  top_force=base.top_force)
    p, save = ChainProblem.from_chain(chain), record_contacts(chain, 0, 10)
    t = 80e-6  # the striker lands at about 112 us
    sol = solve(p, t, save=save)
    assert sol.final_u[0] == pytest.approx(0.89 * t + 0.5 * g * t * t, rel=1e-12)
    assert sol.final_v[0] == pytest.approx(0.89 + g * t, rel=1e-12)
    assert default_step(p, SRKN, 1e-4).head == 1
    landed = solve(p, 0.3e-3, save=save)
    ref = solve(p, 0.3e-3, dt=contact_time_scale(p) / 300, save=save)
    # the pulse the landing sends down: a landing off in time or speed would show here
    err = np.max(np.abs(landed.forces["c10"] - ref.forces["c10"])) / np.max(ref.forces["c10"])
    assert err < 1e-4, err  # the default accuracy


def test_a_drift_of_one_substep_still_feels_the_striker():
    # at accuracy 1e-3 the shortest drifts of a step fit in one head substep: they must
    # still integrate the striker's contact (not take it for free flight)
    chain = ptfe_rig(n=30)
    p, save = ChainProblem.from_chain(chain), record_contacts(chain, 5, 15, 25)
    st = default_step(p, SRKN, 1e-3)
    assert st.head == 1 and 1 in st.substeps(st.dt, SRKN.drifts)
    ref = solve(p, 0.45e-3, dt=contact_time_scale(p) / 300, save=save)
    sol = solve(p, 0.45e-3, accuracy=1e-3, save=save)
    err = max(np.max(np.abs(sol.forces[k] - ref.forces[k])) / np.max(np.abs(ref.forces[k])) for k in ref.forces)
    assert err < 1e-3, err
