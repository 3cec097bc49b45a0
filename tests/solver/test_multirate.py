"""The multirate head: a stiff striker contact substepped, the chain at its own step."""
import numpy as np
import pytest
from chains import ptfe_rig, record_contacts, steel_sonic_vacuum

from rig import ChainProblem, solve
from rig.solver.methods import method
from rig.solver.solution import relative_error
from rig.solver.stepsize import (
    HEAD_SUBSTEP,
    Stepping,
    contact_time_scale,
    head_contacts,
    stepping_at,
)

SRKN = method("srkn6b")


def _reference(p, t_end, save):
    return solve(p, t_end, dt=stepping_at(p, contact_time_scale(p, head_contacts(p) + 1) / 1000), save=save,
                 estimate=False)


def test_the_head_is_the_striker_and_the_contacts_that_open_at_speed():
    from chains import STEEL

    from rig import Bead, Chain, Striker, Wall

    p = ChainProblem.from_chain(ptfe_rig(n=30))
    assert head_contacts(p) == 1  # the alumina striker on the steel bead; the PTFE contacts carry the magnet
    st = stepping_at(p, 2e-6)
    assert st.head == 1 and st.inner_dt == pytest.approx(HEAD_SUBSTEP * 2e-6 * contact_time_scale(p)
                                                         / contact_time_scale(p, 2))
    # sonic vacuum: the unloaded contacts behind the striker open as the beads fly apart
    assert head_contacts(ChainProblem.from_chain(steel_sonic_vacuum(n=40))) == 3
    loaded = Chain([Bead(**STEEL)] * 40, striker=Striker("steel316", "0.4501 g", "0.44 m/s"), wall=Wall(),
                   gravity=0, top_force=2.38)
    assert head_contacts(ChainProblem.from_chain(loaded)) == 1
    assert head_contacts(ChainProblem.from_chain(ptfe_rig(n=30, striker=False))) == 0


@pytest.mark.parametrize("acc", [1e-4, 1e-5])
def test_the_accuracy_contract_on_a_struck_chain(acc):
    # the delivered error of every recorded contact lies between acc/10 and acc, and the
    # solution's estimate within a factor 3 of it
    chain = ptfe_rig(n=30)
    p, save = ChainProblem.from_chain(chain), record_contacts(chain, 5, 15, 25)
    ref = _reference(p, 0.45e-3, save)
    sol = solve(p, 0.45e-3, accuracy=acc, save=save)
    err = relative_error(sol.forces, ref.forces)
    assert acc / 10 <= err <= acc, (acc, err)
    assert 1 / 3 <= sol.stats.error_estimate / err <= 3, (sol.stats.error_estimate, err)
    assert sol.stats.momentum_error < 1e-10


def test_impacts_resolved_make_the_error_a_power_of_the_step():
    # the striker's impacts and the opening contacts behind it are resolved by the head: the
    # error falls as a regular power of the step, each halving dividing it by 8 to 32
    # (order 3 to 5; what the estimate relies on), never above the single-rate solve's,
    # whose error jumps by factors of 1 to 30 from one halving to the next
    chain = steel_sonic_vacuum(n=40)
    p, save = ChainProblem.from_chain(chain), record_contacts(chain, 20, 30)
    ref = _reference(p, 0.3e-3, save)
    tau = contact_time_scale(p, head_contacts(p) + 1)
    errs = []
    for r in (4, 8, 16, 32):
        resolved = relative_error(solve(p, 0.3e-3, dt=stepping_at(p, tau / r), save=save, estimate=False).forces,
                                  ref.forces)
        single = relative_error(solve(p, 0.3e-3, dt=tau / r, save=save, estimate=False).forces, ref.forces)
        assert resolved <= single, (r, resolved, single)
        errs.append(resolved)
    for coarse, fine in zip(errs, errs[1:]):
        assert 8 <= coarse / fine <= 32, errs


def test_head_substeps_converge_to_the_exact_head_flow():
    # the outer step fixed, the head's substep refined: the solution converges to the one with
    # the exact head flow (a substep of 2 ns), and the head's error stays far below the outer
    # step's own (4.6e-7 against the converged reference)
    chain = ptfe_rig(n=30)
    p, save = ChainProblem.from_chain(chain), record_contacts(chain, 10)
    exact = solve(p, 0.3e-3, dt=Stepping(2e-6, 1, 2e-9), save=save, estimate=False)
    errs = [relative_error(solve(p, 0.3e-3, dt=Stepping(2e-6, 1, inner), save=save, estimate=False).forces,
                           exact.forces) for inner in (1e-6, 2.5e-7, 6.25e-8)]
    assert errs[0] > errs[1] > errs[2] and errs[2] < errs[0] / 100, errs
    assert errs[0] < 1e-7, errs
    outer = relative_error(exact.forces, _reference(p, 0.3e-3, save).forces)
    assert outer > 10 * errs[0], (outer, errs)


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
    assert head_contacts(p) == 1
    landed = solve(p, 0.3e-3, save=save)
    ref = _reference(p, 0.3e-3, save)
    # the pulse the landing sends down: a landing off in time or speed would show here
    err = np.max(np.abs(landed.forces["c10"] - ref.forces["c10"])) / np.max(ref.forces["c10"])
    assert err < 1e-4, err  # the default accuracy


def test_a_drift_of_one_substep_still_feels_the_striker():
    # a substep as long as the outer step: the shortest drifts of a step fit in one head
    # substep, and must still integrate the striker's contact (not take it for free flight)
    chain = ptfe_rig(n=30)
    p, save = ChainProblem.from_chain(chain), record_contacts(chain, 5, 15, 25)
    st = Stepping(2e-6, 1, 2e-6)
    assert 1 in st.substeps(st.dt, SRKN.drifts)
    ref = _reference(p, 0.45e-3, save)
    sol = solve(p, 0.45e-3, dt=st, save=save, estimate=False)
    assert relative_error(sol.forces, ref.forces) < 1e-3


def test_a_pass_without_a_head_compiles_no_head_flow(tmp_path):
    """bundles.Method.multirate, a Constant: the batched pass handed 0 (no head) is compiled
    without the head flow (about 8 s of a cold study's compile), in a fresh process with an
    empty cache; the head flow's kernels never compiled."""
    import os
    import subprocess
    import sys
    from pathlib import Path

    probe = ("import numpy as np\nfrom numerics.dispatcher import Constant\n"
             "from rig.model.contact import HERTZ\nfrom rig.solver.kernels import ensemble_passes, multirate\n"
             "from rig.solver.methods import method\nfrom rig.solver.problem import CONTACT_ROWS, STATE_ROWS\n"
             "nb, W = 8, 4\nm = method('srkn6b')\nz = np.zeros((nb, W))\n"
             "ensemble_passes.kick_drift_forces(z, z.copy(), np.ones((nb, W)), np.zeros((nb + 1, W)), np.ones((nb, W)),"
             " np.full((nb, W), 1e-7), np.zeros((nb + 1, W)), 1e-9, 1e-9, 0, Constant(0), np.array(m.drifts),"
             " np.array(m.kicks), 1, np.zeros((2, 3, 1, W)), np.zeros((5, W)), Constant(HERTZ),"
             " np.full((len(CONTACT_ROWS), nb, W), 1.5), np.zeros((len(STATE_ROWS), nb, W)), nb)\n"
             "print(len(ensemble_passes.kick_drift_forces.signatures), len(multirate.head_flow.signatures))")
    done = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True,
                          cwd=Path(__file__).resolve().parents[2], env=dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path)))
    assert done.stdout.split() == ["1", "0"]
