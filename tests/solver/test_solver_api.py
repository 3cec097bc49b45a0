"""What a solve records and refuses."""
import numpy as np
import pytest
from chains import ptfe_rig, steel_sonic_vacuum

from rig import Chain, ChainProblem, ForceSchedule, RigError, SaveAt, solve


def test_only_the_asked_channels_are_recorded():
    chain = ptfe_rig(n=52)
    rec = SaveAt({"g20": chain.gauge_probe(19), "g29": chain.gauge_probe(28), "wall": chain.wall_probe()})
    sol = solve(chain, 1e-3, save=rec)
    n = int(round(1e-3 / rec.sample_interval)) + 1
    assert set(sol.forces) == {"g20", "g29", "wall"}
    assert all(f.shape == (n,) for f in sol.forces.values())
    assert sol.frames is None
    assert sol.recorded_bytes == 3 * n * 8  # three force channels, not the whole chain


def test_frames_only_when_asked():
    chain = ptfe_rig(n=10)
    sol = solve(chain, 1e-4, save=SaveAt({}, frame_interval=1e-5))
    assert sol.frames.shape == (11, 12)  # striker + magnetic bead + 10 beads
    assert np.all(np.diff(sol.frames[0]) > 0)  # ordered down the tube


def test_gauge_reads_the_mean_of_its_two_contacts():
    chain = ptfe_rig(n=20)
    rec = SaveAt({"g": chain.gauge_probe(8), "a": chain.contact_probe(8), "b": chain.contact_probe(9)})
    sol = solve(chain, 3e-4, save=rec)
    assert np.allclose(sol.forces["g"], 0.5 * (sol.forces["a"] + sol.forces["b"]), rtol=1e-13, atol=1e-15)


def test_no_magnet_no_magnet_term():
    p = ChainProblem.from_chain(ptfe_rig(n=5, top_force=0.0))
    assert p.sched_t.size == 0
    assert np.allclose(p.bias[1:-1], 9.80665)  # gravity alone, on the magnetic bead too


def test_scheduled_magnet_force_balances_energy_and_momentum():
    sched = ForceSchedule((0.0, 2e-4, 4e-4), (2.38, 4.25, 4.25))
    chain = ptfe_rig(n=20, top_force=sched, striker=False)
    p, save = ChainProblem.from_chain(chain), SaveAt({"wall": chain.wall_probe()})
    coarse, fine = (solve(p, 6e-4, dt=dt, save=save) for dt in (4e-7, 1e-7))
    for sol in (coarse, fine):
        assert sol.stats.momentum_error < 1e-10  # the schedule's impulse is exact
    # the magnet's work is summed by the trapezoidal rule: the balance closes as O(dt^2)
    assert fine.stats.energy_error < coarse.stats.energy_error / 16 * 1.5
    assert fine.stats.energy_error < 1e-6
    assert fine.forces["wall"][-1] > fine.forces["wall"][0] + 1.0  # the extra load arrives


def test_dissipative_law_loses_energy_and_is_off_by_default():
    assert steel_sonic_vacuum(n=5).law.name == "hertz"
    from chains import STEEL

    from rig import Bead, Striker
    lossy = Chain([Bead(**STEEL)] * 30, striker=Striker("steel316", "0.4501 g", "0.44 m/s"),
                  gravity=0, contact_law="kuwabara-kono", damping_time=1e-7)
    sol = solve(lossy, 2e-4)
    kept = sol.final_body_energies().sum() / (0.5 * 0.4501e-3 * 0.44**2)
    assert 0.5 < kept < 0.999


@pytest.mark.parametrize("t_end", [0.0, -1e-3, float("nan")])
def test_end_time_must_be_positive(t_end):
    with pytest.raises(RigError, match="t_end"):
        solve(ptfe_rig(n=3), t_end)


def test_bad_chain_inputs():
    from rig import Bead
    with pytest.raises(RigError, match="chain.beads"):
        Chain([])
    with pytest.raises(RigError, match="chain.wall"):
        Chain([Bead("ptfe", "4.76 mm")])  # gravity but nothing to rest on
    with pytest.raises(RigError, match="probe.contact"):
        steel_sonic_vacuum(n=5).contact_probe(5)  # no wall, so no contact 5
    with pytest.raises(RigError, match="method"):
        solve(ptfe_rig(n=3), 1e-4, method="rk4")
    with pytest.raises(RigError, match="accuracy"):
        solve(ptfe_rig(n=3), 1e-4, accuracy=2.0)


def test_what_a_solve_is_given_is_checked_in_one_line():
    """A new user's trial: probes of contacts the chain does not have recorded 0 N (the
    kernel read outside its arrays), a dict for save or a float head gave tracebacks, a
    record larger than the machine was a MemoryError, numpy's scalars were refused, and
    accuracy below 1e-10 ran the control for minutes."""
    from rig.model.chain import Probe
    from rig.solver.stepsize import Stepping

    c, big = ptfe_rig(n=20), ptfe_rig(n=60)
    for kw, message in [
        (dict(save=SaveAt({"x": big.contact_probe(50)})), "save['x'] = 'contact 50': contacts 0..21 of this chain"),
        (dict(save=SaveAt({"x": Probe((-1,), (1.0,))})), "save['x'] = 'contact -1': contacts 0..21"),
        (dict(save={"x": c.contact_probe(1)}), "save = 'dict': a SaveAt"),
        (dict(save=SaveAt({"c": c.contact_probe(5)}, sample_interval=1e-16)), "more than this machine's"),
        (dict(save=SaveAt({"c": c.contact_probe(5)}, frame_interval=1e-14)), "frames), more than this machine's"),
        (dict(accuracy=1e-13), "accuracy = 1e-13: relative accuracy target in [1e-10, 0.1]"),
        (dict(dt=True), "dt = True: time step must be a finite number > 0 s"),
    ]:
        with pytest.raises(RigError) as exc:
            solve(c, 2e-4, **kw)
        assert message in str(exc.value), (kw, str(exc.value))
    for kw, message in [(dict(head=2.0), "dt.head = 2.0"), (dict(head=-1), "dt.head = -1"),
                        (dict(head=1, inner_dt=0.0), "dt.inner_dt = 0.0"),
                        (dict(head=1, inner_dt=float("nan")), "dt.inner_dt = nan")]:
        with pytest.raises(RigError) as exc:
            Stepping(2e-8, **kw)
        assert message in str(exc.value)
    sol = solve(c, np.float32(2e-4), save=SaveAt({"c": c.contact_probe(5)}), dt=np.float64(1e-7), estimate=False)
    assert sol.stats.steps == 2000


def test_a_solve_that_blows_up_reports_it_and_solve_refuses_it_in_one_line():
    """integrate_at returns what happened (status UNSTABLE, where and at what step); the
    solve functions raise Unstable from that status, with the same message."""
    from rig.solver.methods import method
    from rig.solver.run import Unstable, integrate_at
    from rig.solver.solution import Status
    from rig.solver.stepsize import Stepping, contact_time_scale

    p = ChainProblem.from_chain(steel_sonic_vacuum(n=20))
    stepping = Stepping(10 * contact_time_scale(p))  # beyond the stability limit (about 1.6 contact times)
    sol = integrate_at(p, 5e-4, SaveAt(), method("srkn6b"), stepping)
    assert sol.status is Status.UNSTABLE and not sol.success
    assert sol.message.startswith(Status.UNSTABLE.message) and "near t = " in sol.message
    assert "\n" not in sol.message
    with pytest.raises(Unstable, match=r"became unstable .* \(near t = ") as err:
        Unstable.check(sol, stepping)
    assert str(err.value) == sol.message and err.value.stepping is stepping
    good = integrate_at(p, 5e-4, SaveAt(), method("srkn6b"), Stepping(contact_time_scale(p) / 6))
    assert good.status is Status.SUCCESS and good.success and good.message == Status.SUCCESS.message
    assert Unstable.check(good, stepping) is good
