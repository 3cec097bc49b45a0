"""The rig starts from exact static equilibrium: nothing moves before impact."""
import numpy as np
from chains import ptfe_rig

from rig import ChainProblem, SaveAt, solve
from rig.solver.solution import relative_error


def test_published_ptfe_chain_at_rest_stays_at_rest():
    # 52 PTFE beads + magnetic bead, gravity and 2.38 N, no striker: after 2 ms no bead
    # moves faster than 1e-9 m/s (acceptance of the static start).
    chain = ptfe_rig(top_force=2.38, striker=False)
    p, save = ChainProblem.from_chain(chain), SaveAt({"wall": chain.wall_probe()})
    sol = solve(p, 2e-3, save=save)
    assert np.max(np.abs(sol.final_v)) < 1e-9
    # the wall carries the weight of everything plus the magnet force, unchanged
    expected = 9.80665 * chain.masses.sum() + 2.38
    assert np.max(np.abs(sol.forces["wall"] - expected)) < 1e-9 * expected


def test_static_forces_are_weight_above_plus_magnet():
    chain = ptfe_rig(n=5, top_force=2.38)
    F = chain.static_forces()
    assert F[0] == 0.0  # the striker just touches
    m = chain.masses
    assert np.allclose(F[1:], 9.80665 * np.cumsum(m) + 2.38, rtol=1e-15)
    # the Hertz law at the static overlaps gives back the static forces
    A = chain.contact_constants()
    d0 = chain.static_overlaps()
    assert np.allclose(A[1:] * d0[1:] ** 1.5, F[1:], rtol=1e-13)


def test_a_record_where_nothing_moves_is_not_refined_down_to_rounding():
    # before anything moves a record's forces differ between steps only by rounding (about
    # 1e-16 of the static force): the accuracy control must not read that as an error of
    # order one relative to a "dynamic peak" of the same size, and halve its step again
    # and again (a free-falling striker once took 45,000 steps for 80 us this way)
    chain = ptfe_rig(n=10, top_force=2.38, striker=False)
    p, save = ChainProblem.from_chain(chain), SaveAt({"wall": chain.wall_probe(), "c5": chain.contact_probe(5)})
    sol = solve(p, 1e-4, save=save)
    assert sol.stats.attempts == 1 and sol.stats.error_estimate < 1e-6
    wall = sol.forces["wall"]
    rounded = {"wall": wall * (1 + 2.2e-16), "c5": sol.forces["c5"]}
    assert relative_error(rounded, sol.forces) < 1e-6
    # a pulse a billionth of the static force high is still a pulse, measured against itself
    moved = dict(sol.forces, wall=wall + 2e-9 * wall[0] * (np.arange(wall.size) > wall.size // 2))
    assert relative_error(sol.forces, moved) > 0.4


def test_a_short_chain_is_balanced_by_the_interpreter_to_the_compiled_kernels_bits(monkeypatch):
    """One short chain's rest balance runs interpreted (numerics.jit.interpreted: no compile
    on a cold cache), a batch's compiled: the same loads and overlaps to the last bit, on
    chains whose balance moves numbers (the nudges run) and whose exponents are not all 3/2."""
    from chains import PTFE, STEEL, steel_sonic_vacuum

    import rig.solver.problem as problem
    import rig.solver.rest as rest
    from numerics.jit import interpreted
    from numerics.threads import over_threads
    from rig import Bead, Chain, MagneticBead, Striker, Wall
    from rig.solver.kernels.forces import balance_at_rest

    seen = []
    monkeypatch.setattr(problem, "balance_at_rest", lambda *arrays: seen.append([a.copy() for a in arrays]))
    chains = [ptfe_rig(), ptfe_rig(n=300, striker=False), steel_sonic_vacuum(n=40, wall=True),
              Chain([MagneticBead()] + [Bead(**PTFE)] * 30, striker=Striker("alumina", "0.47 g", "0.89 m/s"),
                    wall=Wall(), top_force=2.38, contact_exponent=1.75),
              Chain([Bead(**STEEL)] * 50, striker=Striker("steel316", "0.4501 g", "0.5 m/s"), wall=Wall())]
    for chain in chains:
        ChainProblem.from_chain(chain)
    moved = np.zeros(2, dtype=int)
    for load, A, d0, expo, invm in seen:
        assert A.shape[0] == 1 and A.shape[1] <= rest.INTERPRETED_BODIES  # the interpreter's case
        by_hand = [a.copy() for a in (load, d0)]
        interpreted(balance_at_rest)(0, 1, by_hand[0], A, by_hand[1], expo, invm, rest.REST_TOLERANCE,
                                     rest.NUDGES)
        compiled = [a.copy() for a in (load, d0)]
        over_threads(1, balance_at_rest, compiled[0], A, compiled[1], expo, invm, rest.REST_TOLERANCE,
                     rest.NUDGES)
        assert all(np.array_equal(x, y) for x, y in zip(by_hand, compiled))
        moved += [np.count_nonzero(compiled[0] != load), np.count_nonzero(compiled[1] != d0)]
    assert np.all(moved > 0)  # loads and overlaps moved: the rounding and the nudges ran, in both
