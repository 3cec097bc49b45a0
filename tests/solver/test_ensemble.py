"""The batched kernel against single shots: same step, same numbers."""
import numpy as np
import pytest
from chains import ptfe_rig, record_contacts

from rig import ChainProblem, RigError, solve
from rig.solver.ensemble import solve_ensemble
from rig.solver.stepsize import head_contacts, stepping_at

SAVE = record_contacts(ptfe_rig(n=20), 5, 14, 21)


def _problems(n):
    out = []
    for k in range(n):
        chain = ptfe_rig(n=20, top_force=2.38 + 0.05 * k, velocity=f"{0.6 + 0.03 * k} m/s")
        out.append(ChainProblem.from_chain(chain))
    return out


@pytest.mark.parametrize("width", [4, 8])
def test_batched_kernel_agrees_with_single_shots(width):
    probs = _problems(11)  # not a multiple of the width: the last chunk is padded
    dt = stepping_at(probs[0], 2e-6)
    assert dt.head == head_contacts(probs[0]) == 1  # the alumina striker: the head runs in both kernels
    ens = solve_ensemble(probs, 0.8e-3, save=SAVE, dt=dt, width=width)
    for k, p in enumerate(probs):
        single = solve(p, 0.8e-3, dt=dt, save=SAVE, estimate=False)
        for name, f in single.forces.items():
            assert np.array_equal(ens.forces[name][k], f), name  # the same bits
        assert ens.reports[k].energy_error == single.stats.energy_error
        assert ens.reports[k].momentum_error <= 1e-10


@pytest.mark.parametrize("width", [1, 4])
def test_an_ensemble_leaves_the_shots_it_solves_as_they_were(width):
    # the kernel integrates its chunks' displacements and velocities in place: the shots'
    # own arrays must reach it as copies, at any width (a chunk of one shot is contiguous
    # already), so that solving the same shots again gives the same records
    from rig.solver.problem import ProblemArrays

    shots = ProblemArrays.of(_problems(4))
    u0, v0 = shots.u0.copy(), shots.v0.copy()
    dt = stepping_at(shots.layout, 2e-6)
    first = solve_ensemble(shots, 0.2e-3, save=SAVE, dt=dt, width=width)
    assert np.array_equal(shots.u0, u0) and np.array_equal(shots.v0, v0)
    again = solve_ensemble(shots, 0.2e-3, save=SAVE, dt=dt, width=width)
    assert all(np.array_equal(again.forces[name], f) for name, f in first.forces.items())


def test_ensemble_refuses_mixed_topologies_and_schedules():
    from rig import ForceSchedule
    a = _problems(1)[0]
    chain = ptfe_rig(n=21)
    b = ChainProblem.from_chain(chain)
    with pytest.raises(RigError, match="one chain topology"):
        solve_ensemble([a, b], 1e-4, save=SAVE, dt=1e-7)
    sched = ptfe_rig(n=20, top_force=ForceSchedule((0, 1e-4), (2.38, 3.0)))
    with pytest.raises(RigError, match="constant loads only"):
        solve_ensemble([ChainProblem.from_chain(sched)], 1e-4, save=SAVE, dt=1e-7)


def test_a_solve_within_solved_as_batches_is_the_single_shot_solve_to_the_last_bit():
    """A study's solves of one shot (rig/study/nominal.py) run through the batched kernel as a
    batch of one: the accuracy control's choice, the records, the final state and the report
    as the single-shot kernel's; a solve it cannot take (frames) stays the single kernel's."""
    from rig.solver import ensemble

    p = _problems(1)[0]
    single = solve(p, 0.8e-3, save=SAVE)
    calls = []
    batched = ensemble.batch_of_one

    def counted(*args, **kw):
        calls.append(args[0])
        return batched(*args, **kw)

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(ensemble, "batch_of_one", counted)
        with ensemble.solved_as_batches():
            as_batch = solve(p, 0.8e-3, save=SAVE)
            assert len(calls) == as_batch.stats.attempts * 2  # each try of the accuracy control and its companion
            framed = solve(p, 0.2e-3, save=record_contacts(ptfe_rig(n=20), 5, frame_interval=1e-5))
            assert ensemble.ONE_SHOT_KERNEL.get() == "batched" and framed.frames is not None
        assert ensemble.ONE_SHOT_KERNEL.get() == "single"
    assert as_batch.stats.dt_s == single.stats.dt_s and as_batch.stats.error_estimate == single.stats.error_estimate
    for name, f in single.forces.items():
        assert np.array_equal(as_batch.forces[name], f), name
    assert np.array_equal(as_batch.final_u, single.final_u) and np.array_equal(as_batch.final_v, single.final_v)
    assert as_batch.stats.energy_error == single.stats.energy_error
    assert as_batch.stats.bodies_stepped == single.stats.bodies_stepped
