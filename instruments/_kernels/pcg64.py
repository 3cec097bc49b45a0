"""numpy's default generator, compiled inline (numba): ``seeded(seed)`` is the state of
np.random.default_rng(seed) (a SeedSequence of the integer seed feeding PCG64), and
``standard_normal``, ``next_double`` and ``normals`` give Generator.standard_normal's and
Generator.random's numbers, draw for draw, from it.

A batch's instruments draw tens of thousands of normals per shot. numba's own Generator
gives the same numbers, but it reaches the bit generator through a function pointer on
every draw, and handing it a Generator costs a Python object's unboxing per call; numpy's
default_rng(seed) costs about 14 us of Python per shot. Here the state is four uint64
words (state high, state low, increment high, increment low), the 128-bit step is LLVM's
i128 arithmetic and the ziggurat is numpy's (its tables are numba's copy of numpy's).
tests/instruments/test_pcg64.py compares the bits with numpy's.

PCG64 (O'Neill 2014, as numpy implements it): s <- s a + c mod 2^128, then the output
XSL-RR: (high ^ low) rotated right by the top 6 bits of s.
"""
import numpy as np
from llvmlite import ir
from numba import types
from numba.extending import intrinsic
from numba.np.random._constants import fi_double, ki_double, wi_double, ziggurat_nor_inv_r, ziggurat_nor_r

from numerics.jit import jit

MULTIPLIER = 0x2360ED051FC65DA44385DF649FCCF645  # PCG's default 128-bit LCG multiplier
_I128, _I64 = ir.IntType(128), ir.IntType(64)
U = np.uint64
M32 = U(0xFFFFFFFF)
# numpy's SeedSequence: hash constants (uint32) and the pool of four words
INIT_A, MULT_A, INIT_B, MULT_B = U(0x43B0D7E5), U(0x931E8875), U(0x8B51F9DD), U(0x58F38DED)
MIX_MULT_L, MIX_MULT_R, XSHIFT = U(0xCA01F9DD), U(0x4973F715), U(16)


@intrinsic
def lcg128(typingctx, hi, lo, inc_hi, inc_lo):
    """(hi, lo) of s a + c mod 2^128 for s = (hi, lo), c = (inc_hi, inc_lo) (uint64 words)."""
    sig = types.UniTuple(types.uint64, 2)(types.uint64, types.uint64, types.uint64, types.uint64)

    def codegen(context, builder, signature, args):
        def wide(h, w):
            return builder.or_(builder.shl(builder.zext(h, _I128), ir.Constant(_I128, 64)), builder.zext(w, _I128))

        s = builder.add(builder.mul(wide(args[0], args[1]), ir.Constant(_I128, MULTIPLIER)), wide(args[2], args[3]))
        high = builder.trunc(builder.lshr(s, ir.Constant(_I128, 64)), _I64)
        return context.make_tuple(builder, signature.return_type, (high, builder.trunc(s, _I64)))

    return sig, codegen


@jit(inline="always")
def next64(st):
    """The next uint64 of state st (uint64[4], advanced in place): step, then XSL-RR."""
    # an intrinsic takes the values in a kernel; its Python signature starts with numba's typing context
    hi, lo = lcg128(st[0], st[1], st[2], st[3])  # type: ignore[call-arg,var-annotated]
    st[0], st[1] = hi, lo
    x = hi ^ lo
    r = hi >> U(58)
    return (x >> r) | (x << ((U(64) - r) & U(63)))


@jit(inline="always")
def next_double(st):
    """Uniform in [0, 1): the top 53 bits of next64 over 2^53 (Generator.random)."""
    return np.float64(next64(st) >> U(11)) * (1.0 / 9007199254740992.0)


@jit(inline="always")
def standard_normal(st):
    """One standard normal, numpy's 256-layer ziggurat (Generator.standard_normal): the low
    8 bits of a draw pick the layer, the next its sign, 52 bits its abscissa; the rare draws
    outside a layer's core take the wedge's or the tail's test."""
    while True:
        r = next64(st)
        idx = r & U(0xFF)
        r >>= U(8)
        rabs = (r >> U(1)) & U(0x000FFFFFFFFFFFFF)
        x = np.float64(rabs) * wi_double[idx]
        if r & U(1):
            x = -x
        if rabs < ki_double[idx]:
            return x
        if idx == 0:
            while True:
                xx = -ziggurat_nor_inv_r * np.log1p(-next_double(st))
                yy = -np.log1p(-next_double(st))
                if yy + yy > xx * xx:
                    return -(ziggurat_nor_r + xx) if (rabs >> U(8)) & U(1) else ziggurat_nor_r + xx
        elif (fi_double[idx - 1] - fi_double[idx]) * next_double(st) + fi_double[idx] < np.exp(-0.5 * x * x):
            return x


@jit(nogil=True)
def normals(st, out):
    """Fill out (float64[::1]; an array of more axes as its flat view, reshape(-1): one
    compiled copy, about 0.8 s each) with standard normals from state st."""
    for i in range(out.shape[0]):
        out[i] = standard_normal(st)


@jit(inline="always")
def _hashmix(value, hash_const):
    value ^= hash_const
    hash_const = (hash_const * MULT_A) & M32
    value = (value * hash_const) & M32
    return value ^ (value >> XSHIFT), hash_const


@jit(inline="always")
def _mix(x, y):
    r = (MIX_MULT_L * x - MIX_MULT_R * y) & M32
    return r ^ (r >> XSHIFT)


@jit(inline="always")
def seeded_by(entropy):
    """(the PCG64 state (uint64[4]) of np.random.default_rng(SeedSequence) whose assembled
    entropy is ``entropy`` (uint64 array of 32-bit words: the seed's, and where it has a
    spawn key, padded with 0 to four words and followed by the key's), the sequence's
    generate_state(1, uint64)[0]). The pool of four 32-bit words is hashed and mixed from
    the words, four uint64 are drawn from it (128-bit seed, 128-bit stream), then PCG's
    seeding: s = 0, c = 2 stream + 1, a step, s += seed, a step."""
    pool = np.empty(4, np.uint64)
    hc = INIT_A
    for i in range(4):
        pool[i], hc = _hashmix(entropy[i] if i < entropy.shape[0] else U(0), hc)
    for i_src in range(4):
        for i_dst in range(4):
            if i_src != i_dst:
                h, hc = _hashmix(pool[i_src], hc)
                pool[i_dst] = _mix(pool[i_dst], h)
    for i_src in range(4, entropy.shape[0]):
        for i_dst in range(4):
            h, hc = _hashmix(entropy[i_src], hc)
            pool[i_dst] = _mix(pool[i_dst], h)
    drawn = np.empty(4, np.uint64)
    hc = INIT_B
    for i in range(8):  # generate_state(4, uint64): eight 32-bit words, little-endian pairs
        v = pool[i % 4] ^ hc
        hc = (hc * MULT_B) & M32
        v = (v * hc) & M32
        v ^= v >> XSHIFT
        drawn[i // 2] = v if i % 2 == 0 else drawn[i // 2] | (v << U(32))
    st = np.empty(4, np.uint64)
    st[2] = (drawn[2] << U(1)) | (drawn[3] >> U(63))
    st[3] = (drawn[3] << U(1)) | U(1)
    st[0], st[1] = lcg128(U(0), U(0), st[2], st[3])  # type: ignore[call-arg]  # an intrinsic: see next64
    lo = st[1] + drawn[1]
    st[0] = st[0] + drawn[0] + (U(1) if lo < st[1] else U(0))
    st[1] = lo
    st[0], st[1] = lcg128(st[0], st[1], st[2], st[3])
    return st, drawn[0]


@jit(nogil=True)
def seeded(seed):
    """The PCG64 state (uint64[4]) of np.random.default_rng(seed), seed an integer in
    [0, 2^63) (its one or two 32-bit words are SeedSequence(seed)'s entropy)."""
    entropy = np.empty(2, np.uint64)
    entropy[0], entropy[1] = U(seed) & M32, U(seed) >> U(32)
    return seeded_by(entropy[:1] if entropy[1] == U(0) else entropy)[0]


@jit(nogil=True)
def spawned_draws(run_entropy, first, uniform, counts, raw, heads):
    """The draws of the streams np.random.default_rng(SeedSequence(seed, spawn_key=(i,)))
    for i = first, first + 1, ...: row s of raw gets stream first + s's draws in turn,
    counts[d] of each kind d, standard normals (Generator.standard_normal) or, where
    uniform[d], uniforms in [0, 1) (Generator.random); heads[s] is that sequence's
    generate_state(1, uint64)[0]. run_entropy: the seed's 32-bit words padded with 0 to
    four (uint64 array), i < 2^32."""
    n = run_entropy.shape[0]
    entropy = np.empty(n + 1, np.uint64)
    for i in range(n):  # element by element: numba's array slice assignment compiles its error message
        entropy[i] = run_entropy[i]
    for s in range(raw.shape[0]):
        entropy[n] = U(first + s)
        st, heads[s] = seeded_by(entropy)
        col = 0
        for d in range(counts.shape[0]):
            for _ in range(counts[d]):
                raw[s, col] = next_double(st) if uniform[d] else standard_normal(st)
                col += 1
