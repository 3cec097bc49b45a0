"""Where the kernels' working arrays lie in memory.

A fused pass of the single-shot kernel (step.fused_run) runs over seven arrays at the
same body index: it stores u, v and f and loads those and invm, A, d0 and load. Two
things about their addresses cost time without changing a bit of the result:

- Alignment. A vector load that straddles two 64-byte cache lines takes two; ``step``
  starts each pass's vector loop at a body index that is a multiple of LINE, which aligns
  every load and store with an array whose element 0 starts a cache line.
- 4 KiB aliasing. The core matches a load against the stores in flight by the low 12 bits
  of their addresses: a load from an address 4096 k bytes away from a recent store's waits
  for that store as if it read what it wrote. A pass that stores array S at body i and
  loads array L at a later body j so meets S's store where L starts 8 (j - i) bytes below
  S modulo 4096. Arrays from the allocator fall anywhere modulo 4096 (numpy's large ones
  all 16 bytes past a page, the same offset): where a loaded array started a few hundred
  bytes below a stored one, the single-shot passes took up to 1.6x as long (the 1,000-bead
  benchmark chain). ``working_arrays`` places the seven arrays in one page-aligned
  workspace at fixed offsets in a 4 KiB page (PAGE_OFFSETS): no array starts within 640
  bytes (80 bodies, more than the stores in flight) below a stored one.
"""
import numpy as np

LINE = 8  # float64s per 64-byte cache line
PAGE = 4096  # bytes: the span of the address bits a load is matched on against the stores in flight
# Offsets (bytes, modulo PAGE) of invm, A, d0, load, then the stored arrays u, v, f.
PAGE_OFFSETS = (0, 448, 896, 1344, 2048, 2816, 3584)


def working_arrays(*arrays: np.ndarray) -> list:
    """Copies of the float64 arrays invm, A, d0, load, u, v, f (in that order) in one
    workspace, array k starting at byte PAGE_OFFSETS[k] of a 4 KiB page (module doc).

    The batched kernel (ensemble.py) takes its arrays as they come: with each chunk's
    arrays placed so, `rig bench mc --baseline` (7 rounds in turns) gave it 0.98 times the
    shots per second of the arrays as they came."""
    sizes = [a.size for a in arrays]
    starts, end = [], 0
    for size, offset in zip(sizes, PAGE_OFFSETS):  # elements; each array at its offset in a page
        start = end + (offset // 8 - end) % (PAGE // 8)
        starts.append(start)
        end = start + size
    buf = np.empty(end + PAGE // 8)
    base = (-buf.ctypes.data) % PAGE // 8  # the first element of buf on a page boundary
    out = []
    for a, start in zip(arrays, starts):
        x = buf[base + start:base + start + a.size].reshape(a.shape)
        x[...] = a
        out.append(x)
    return out
