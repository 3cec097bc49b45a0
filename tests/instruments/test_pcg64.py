"""The compiled generator (instruments/_kernels/pcg64.py) is numpy's default_rng, bit for
bit: its seeding, its standard normals (every branch of the ziggurat: the layers' cores,
the wedges, the tail) and its uniforms, and the state it leaves behind."""
import numpy as np
import pytest

from instruments._kernels import pcg64

SEEDS = [0, 1, 12345, 2**32 - 1, 2**32, 2**62 + 17, 2**63 - 1]


def _state_of(gen) -> tuple:
    s = gen.bit_generator.state["state"]
    return s["state"], s["inc"]


def _as_ints(st) -> tuple:
    return int(st[0]) << 64 | int(st[1]), int(st[2]) << 64 | int(st[3])


@pytest.mark.parametrize("seed", SEEDS)
def test_seeded_is_default_rngs_state(seed):
    assert _as_ints(pcg64.seeded(seed)) == _state_of(np.random.default_rng(seed))


@pytest.mark.parametrize("seed", [3, 2**40 + 5])
def test_normals_are_numpys_to_the_last_bit_and_leave_its_state(seed):
    gen = np.random.default_rng(seed)
    st = pcg64.seeded(seed)
    z = np.empty((4, 250_000))  # a million draws: about 12,000 leave a layer's core, some 100 the tail
    pcg64.normals(st, z.reshape(-1))  # its flat view: the kernel fills 1-D arrays
    expected = gen.standard_normal((4, 250_000))
    assert np.array_equal(z.view(np.uint64), expected.view(np.uint64))
    assert np.abs(z).max() > 3.654  # beyond the ziggurat's base: the tail's branch was taken
    assert _as_ints(st) == _state_of(gen)


def test_uniforms_are_generator_randoms():
    gen = np.random.default_rng(99)
    st = pcg64.seeded(99)
    got = np.array([pcg64.next_double(st) for _ in range(1000)])
    assert np.array_equal(got.view(np.uint64), gen.random(1000).view(np.uint64))



def test_draws_in_pieces_are_the_draws_in_one():
    # a block is drawn ahead: the state left after each piece must be its last draw's, so
    # that pieces of any size (none too) go on with the stream where the last one ended
    gen = np.random.default_rng(7)
    st = pcg64.seeded(7)
    for n in (1, 2, 0, 31, 32, 33, 5, 64, 1000):
        z = np.empty(n)
        pcg64.normals(st, z)
        assert np.array_equal(z.view(np.uint64), gen.standard_normal(n).view(np.uint64))
        assert _as_ints(st) == _state_of(gen)
