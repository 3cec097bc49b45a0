"""Where the single-shot kernel's arrays lie in memory (plain numpy, no numba).

A fused pass (step.fused_run) runs over seven arrays at the same body index: it stores u,
v and f and loads those and invm, A, d0 and load. Two things about their addresses cost
time without changing a bit of the result:

- Alignment. A vector load that straddles two 64-byte cache lines takes two; ``step``
  starts each pass's vector loop at a body index that is a multiple of LINE, which aligns
  every load and store with an array whose element 0 starts a cache line.
- 4 KiB aliasing. The core matches a load against the stores in flight by the low 12 bits
  of their addresses: a load whose address lies a little above a recent store's modulo
  4096 bytes waits for that store as if it depended on it. Seven arrays from the
  allocator fall anywhere modulo 4096: where a loaded array starts a few hundred bytes
  below a stored one, the passes took up to 1.6x as long (measured on the 1,000-bead
  benchmark chain). ``working_arrays`` places the arrays at fixed offsets in a 4 KiB page
  (PAGE_OFFSETS): no array starts within 640 bytes (80 bodies, more than the stores in
  flight) below a stored one.
"""
from __future__ import annotations

import numpy as np

LINE = 8  # float64s per 64-byte cache line
PAGE = 4096  # bytes: the span of the address bits a load is matched on against the stores in flight
# Offsets (bytes, modulo PAGE) of invm, A, d0, load, then the stored arrays u, v, f.
PAGE_OFFSETS = (0, 448, 896, 1344, 2048, 2816, 3584)


def working_arrays(*arrays: np.ndarray) -> list[np.ndarray]:
    """Copies of the 1-d float64 arrays invm, A, d0, load, u, v, f (in that order), in one
    allocation, array k starting at byte PAGE_OFFSETS[k] of a 4 KiB page (module doc)."""
    sizes = [a.shape[0] * 8 for a in arrays]
    starts, end = [], 0
    for size, offset in zip(sizes, PAGE_OFFSETS):
        start = end + (offset - end) % PAGE
        starts.append(start)
        end = start + size
    buf = np.empty((end + PAGE) // 8)
    base = (-buf.ctypes.data) % PAGE // 8  # first element of buf on a page boundary
    out = []
    for a, start in zip(arrays, starts):
        x = buf[base + start // 8: base + start // 8 + a.shape[0]]
        x[:] = a
        out.append(x)
    return out
