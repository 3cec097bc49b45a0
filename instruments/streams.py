"""Many seeded random streams at once: numpy's default generator compiled
(``_kernels/pcg64.py``), so that a study draws every shot's inputs in one call, with the
very numbers that np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(i,)))
gives shot i (tests/instruments/test_pcg64.py compares them)."""
from __future__ import annotations

import numbers

import numpy as np

from ._kernels import pcg64
from .errors import InstrumentError

KINDS = ("normal", "uniform")  # Generator.standard_normal, Generator.random


def _words(n: int) -> list:
    """The 32-bit words of a whole number >= 0, least significant first (0: one word)."""
    words = [n & 0xFFFFFFFF]
    while n >> 32:
        n >>= 32
        words.append(n & 0xFFFFFFFF)
    return words


def spawned_draws(seed: int, first: int, count: int, kinds, sizes) -> tuple:
    """(draws (count, sum(sizes)) float64, heads (count,) uint64): row s holds, in turn,
    sizes[d] draws of kind kinds[d] ("normal": standard normals, "uniform": in [0, 1)) of
    the stream of SeedSequence(seed, spawn_key=(first + s,)), and heads[s] is that
    sequence's generate_state(1, np.uint64)[0]."""
    def whole(value) -> bool:
        return not isinstance(value, bool) and isinstance(value, numbers.Integral) and int(value) >= 0

    if not whole(seed):
        raise InstrumentError(f"seed = {seed!r}: allowed a whole number >= 0")
    if not (whole(first) and whole(count) and first + count <= 2**32):
        raise InstrumentError(f"spawn keys from {first!r}, {count!r} of them: allowed whole numbers, "
                              f"keys 0 to 2^32 - 1")
    if isinstance(kinds, str) or len(kinds) != len(sizes):
        raise InstrumentError(f"kinds = {kinds!r}, sizes = {sizes!r}: allowed two sequences of one length")
    for k, n in zip(kinds, sizes):
        if k not in KINDS:
            raise InstrumentError(f"kind = {k!r}: allowed {', '.join(KINDS)}")
        if not whole(n):
            raise InstrumentError(f"size = {n!r}: allowed a whole number >= 0")
    words = _words(int(seed))
    words += [0] * (4 - len(words))  # numpy pads a spawned sequence's entropy to its pool's four words
    draws = np.empty((count, int(sum(sizes))))
    heads = np.empty(count, np.uint64)
    pcg64.spawned_draws(np.array(words, np.uint64), int(first), np.array([k == "uniform" for k in kinds]),
                        np.array(sizes, np.int64), draws, heads)
    return draws, heads
