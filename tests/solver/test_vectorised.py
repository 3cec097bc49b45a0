"""The hot loops stay vectorised: LLVM's code for each holds vector square roots and vector
arithmetic. A change that loses it (a loop start numba can no longer prove non-negative
brings back its wraparound check, a branch on the data, a call in the loop) fails here,
not months later in a benchmark. numba does not show the code of a cached kernel, so each
is compiled afresh, uncached, from its Python source."""
import re

import numba
import numpy as np
import pytest

from rig.model.contact import HERTZ, KUWABARA_KONO, PLASTIC, POWER
from rig.solver.kernels import dissipation, ensemble_passes, forces, multirate, record, step
from rig.solver.problem import CONTACT_ROWS, STATE_ROWS


def _llvm(kernel, *args) -> str:
    options = {k: v for k, v in kernel.targetoptions.items() if k != "nopython"}  # fastmath, error_model
    fresh = numba.njit(**options, cache=False)(kernel.py_func)
    fresh(*args)
    return "\n".join(fresh.inspect_llvm().values())


def _vector_ops(ir: str) -> set:
    return set(re.findall(r"<(\d+) x double>", ir))


def _chain(nb=64):
    rng = np.random.default_rng(0)
    u = 1e-9 * rng.standard_normal(nb)
    return u, np.zeros(nb), np.ones(nb), np.zeros(nb + 1), np.full(nb, 1e9), np.full(nb, 1e-7), np.zeros(nb)


@pytest.mark.parametrize("law", [HERTZ, KUWABARA_KONO, POWER, PLASTIC])
def test_the_fused_kick_drift_force_pass_is_vectorised(law):
    """POWER and PLASTIC too: their pass is Hertz's (PLASTIC's over each slot's elastic curve),
    the slots it does not give renewed after it."""
    u, v, invm, f, A, d0, _ = _chain()
    ir = _llvm(step.fused_run, u, v, invm, f, A, d0, np.zeros(65), 1e-9, 1e-9, 3, 64, law, np.full(64, 1.5))
    assert re.search(r"llvm\.sqrt\.v\d+f64", ir), "the square roots of the force pass are scalar"
    assert _vector_ops(ir), "no vector arithmetic in the fused pass"


def test_the_closing_kick_is_vectorised():
    u, v, invm, f, *_ = _chain()
    assert _vector_ops(_llvm(step.closing_kick, v, invm, f, 1e-9, 1, v.shape[0])), "the closing kick is scalar"


def test_the_batched_kernel_vectorises_over_shots():
    nb, W = 16, 32
    u = np.zeros((nb, W))
    ir = _llvm(ensemble_passes.contact_row, u, np.ones((nb, W)), np.full((nb, W), 1e-7), np.zeros((nb + 1, W)),
               np.zeros((nb + 1, W)), 3)
    assert re.search(r"llvm\.sqrt\.v\d+f64", ir), "the batched force row is scalar"


def test_the_batched_pass_runs_its_rows_inline():
    """The batched kick-drift-force pass calls a row helper per body: called (not inlined),
    each call costs about as much as a row of 64 shots (the pass ran 2.1x slower so)."""
    from rig.solver.methods import method

    nb, W = 16, 32
    m = method("srkn6b")
    z = np.zeros((nb, W))
    ir = _llvm(ensemble_passes.kick_drift_forces, z, z.copy(), np.ones((nb, W)), np.zeros((nb + 1, W)),
               np.ones((nb, W)), np.full((nb, W), 1e-7), np.zeros((nb + 1, W)), 1e-9, 1e-9, 0, 0, np.array(m.drifts),
               np.array(m.kicks),
               1, np.zeros((2, 3, 1, W)), np.zeros((5, W)), HERTZ, np.full((len(CONTACT_ROWS), nb, W), 1.5),
               np.zeros((len(STATE_ROWS), nb, W)), nb)
    called = set(re.findall(r"call [^@]*@\"?([\w.$]+)", ir))
    assert not [name for name in called if "_row" in name], f"row helpers called, not inlined: {called}"
    assert re.search(r"llvm\.sqrt\.v\d+f64", ir), "the batched force rows are scalar"


def test_the_head_substeps_run_over_the_shots_at_once():
    """The multirate head's substeps (a struck chain's costliest part when each shot took
    them alone: about a quarter of a batched shot) run over every shot of a chunk, masked,
    and vectorise."""
    from rig.solver.methods import method

    W, head = 32, 1
    m = method("srkn6b")
    z = np.zeros((head + 2, W))
    ir = _llvm(multirate._lane_substep, z, z.copy(), np.ones((head + 1, W)), np.zeros((head + 2, W)),
               np.ones((head + 1, W)), np.full((head + 1, W), 1e-7), np.zeros((head + 2, W)), head,
               np.array(m.drifts), np.array(m.kicks), 1e-9, np.zeros(W), np.ones(W), np.zeros(W),
               np.zeros((head, W)))
    assert re.search(r"llvm\.sqrt\.v\d+f64", ir), "the head's substeps are scalar"


def test_the_probe_overlaps_are_vectorised_over_the_shots():
    """An array read inside a branch of an inlined helper (the magnet schedule's kick in
    record.synced_velocity) made numba keep atomic reference counts in the loop: 28 ns per
    shot and contact instead of 1.2, and no vector code."""
    nb, W = 16, 32
    z = np.zeros((nb, W))
    ir = _llvm(record.probe_overlaps, z, z.copy(), np.ones((nb, W)), np.zeros((nb + 1, W)), np.zeros((nb, W)),
               np.array([[3, 4], [9, 0]]), np.array([[0.5, 0.5], [1.0, 0.0]]), 1e-9, 1, -1, 0.0,
               np.zeros((2, 2, W)), np.zeros((2, 2, W)))
    assert _vector_ops(ir), "the probe overlaps are scalar"


def test_the_energy_check_is_vectorised_over_the_shots():
    """With numba's default error model a division checks its divisor for zero, element by
    element, and the loop stays scalar (state_sums divides in numpy's model: inf)."""
    nb, W = 16, 32
    z = np.zeros((nb, W))
    ir = _llvm(forces.state_sums, z, z.copy(), np.ones((nb, W)), z.copy(), np.ones((nb, W)), np.full((nb, W), 1.5),
               np.full((nb, W), 1e-7), np.ones((nb, W)), HERTZ, np.zeros((len(STATE_ROWS), nb, W)), np.zeros(W),
               np.zeros(W), np.zeros(W))
    assert re.search(r"llvm\.sqrt\.v\d+f64", ir), "the elastic energies' square roots are scalar"
    assert re.search(r"fdiv <\d+ x double>", ir), "the overlaps' ratios to their limits are scalar"


def test_the_viscous_contacts_flow_is_vectorised():
    """Dissipation's contacts (Kuwabara-Kono, dashpot): the coefficients' square roots and
    the midpoint substeps over the flat (bodies x shots) arrays."""
    nb = 64
    u, v = np.zeros((nb, 1)), np.zeros((nb, 1))
    ones = np.ones((nb, 1))
    con = np.zeros((len(CONTACT_ROWS), nb, 1))
    con[0], con[1], con[3] = 1.5, 1e-6, 1.0
    ir = _llvm(dissipation._contacts, u, v, ones, 1e9 * ones, 1e-7 * ones, con, HERTZ,
               np.zeros((len(STATE_ROWS), nb, 1)), 1e-9, 1, nb - 1, np.zeros((5, nb + 1, 1)), np.zeros(1))
    assert re.search(r"llvm\.sqrt\.v\d+f64", ir), "the viscous coefficients' square roots are scalar"
    assert _vector_ops(ir), "no vector arithmetic in the viscous substeps"
    flat = np.zeros(nb + 1)
    assert _vector_ops(_llvm(dissipation._viscous, flat, flat, flat, flat, np.uint64(1), nb)), \
        "the viscous forces are scalar"
