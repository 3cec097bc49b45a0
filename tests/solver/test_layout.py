"""Where the single-shot kernel's arrays lie (rig/solver/kernels/layout.py): aligned to
cache lines, at fixed offsets in a 4 KiB page, and no bit of a solve depends on it."""
import numpy as np
import pytest
from chains import ptfe_rig

import rig.solver.run as run
from rig import Bead, Chain, ChainProblem, SaveAt, Striker, Wall
from rig.bench.kernel_cost import in_motion
from rig.solver.kernels.layout import PAGE, PAGE_OFFSETS, working_arrays
from rig.solver.methods import method
from rig.solver.stepsize import Stepping, contact_time_scale, stepping_at

STEEL = dict(material="steel316", diameter="4.76 mm", mass="0.4501 g")


def test_working_arrays_are_separate_copies_at_their_page_offsets():
    rng = np.random.default_rng(3)
    arrays = [rng.standard_normal(n) for n in (5, 1001, 1000, 1001, 4097, 3, 1002)]
    kept = [a.copy() for a in arrays]
    out = working_arrays(*arrays)
    for k, (a, x) in enumerate(zip(arrays, out)):
        assert np.array_equal(x, a) and x.dtype == np.float64 and x.flags.c_contiguous and x.flags.writeable
        assert x.ctypes.data % PAGE == PAGE_OFFSETS[k]
        for y in out[k + 1:]:
            assert not np.shares_memory(x, y)
    for x in out:
        x[:] = 0.0
    assert all(np.array_equal(a, b) for a, b in zip(arrays, kept)), "working_arrays wrote to the caller's arrays"


def test_no_array_starts_just_below_a_stored_one():
    """The page offsets keep every array (invm, A, d0, load, u, v, f) out of the 640 bytes
    below a stored one (u, v, f), modulo a page: the module doc's rule."""
    stored = PAGE_OFFSETS[4:]
    for s in stored:
        for other in PAGE_OFFSETS:
            if other != s:
                assert (s - other) % PAGE > 640, (s, other)
    assert all(o % 64 == 0 for o in PAGE_OFFSETS) and len(set(PAGE_OFFSETS)) == 7


def _misplaced(*arrays):
    """Copies that start 8 bytes past a cache line, each 64 bytes after the last modulo a
    page: every pass starts its vector loop misaligned, with the stored arrays just above
    the loaded ones (the layout the module doc warns of)."""
    out = []
    for k, a in enumerate(arrays):
        buf = np.empty(a.shape[0] + 2 * PAGE // 8)
        start = ((8 + 64 * (len(arrays) - k) - buf.ctypes.data) % PAGE) // 8
        x = buf[start:start + a.shape[0]]
        x[:] = a
        out.append(x)
    return out


def _cases():
    steel = Bead(**STEEL)
    long_chain = Chain([steel] * 2100, striker=Striker("steel316", "0.4501 g", "0.44 m/s"), wall=Wall(), gravity=0,
                       top_force=2.38)
    return [
        ("precompressed, wall", Chain([steel] * 80, striker=Striker("steel316", "0.4501 g", "0.44 m/s"),
                                      wall=Wall(), gravity=0, top_force=2.38), False, 2e-4, False),
        ("magnet and gravity, multirate head", ptfe_rig(n=40, top_force=2.38), False, 3e-4, True),
        ("more than one block of the wavefront, every bead moving", long_chain, True, 2e-5, False),
    ]


@pytest.mark.parametrize("label,chain,moving,t_end,head", _cases(), ids=[c[0] for c in _cases()])
def test_where_the_arrays_lie_changes_no_bit(monkeypatch, label, chain, moving, t_end, head):
    p = ChainProblem.from_chain(chain)
    p = in_motion(p) if moving else p
    dt = contact_time_scale(p) / 6
    stepping = stepping_at(p, dt) if head else Stepping(dt)
    assert stepping.head > 0 or not head
    save = SaveAt({"c2": chain.contact_probe(2), "c9": chain.contact_probe(9)}, sample_interval=1e-6,
                  frame_interval=1e-5)
    m = method("srkn6b")
    placed = run.integrate_at(p, t_end, save, m, stepping)
    monkeypatch.setattr(run, "working_arrays", _misplaced)
    misplaced = run.integrate_at(p, t_end, save, m, stepping)
    for name in save.names:
        assert np.array_equal(placed.forces[name].view(np.uint64), misplaced.forces[name].view(np.uint64)), name
    assert np.array_equal(placed.frames.view(np.uint64), misplaced.frames.view(np.uint64))
    assert np.array_equal(placed.final_u.view(np.uint64), misplaced.final_u.view(np.uint64))
    assert np.array_equal(placed.final_v.view(np.uint64), misplaced.final_v.view(np.uint64))
    assert placed.stats.energy_error == misplaced.stats.energy_error
