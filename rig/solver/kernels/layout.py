"""Where the kernels' working arrays lie in memory.

A fused pass (step.fused_run; the batched kernel's rows) runs over seven arrays at the
same body index: it stores u, v and f and loads those and invm, A, d0 and load. Two
things about their addresses cost time without changing a bit of the result:

- Alignment. A vector load that straddles two 64-byte cache lines takes two; ``step``
  starts each pass's vector loop at a body index that is a multiple of LINE, which aligns
  every load and store with an array whose element 0 starts a cache line (the batched
  kernel's rows of 8 to 128 shots start lines when the array does).
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

from instruments.jit import jit

LINE = 8  # float64s per 64-byte cache line
PAGE = 4096  # bytes: the span of the address bits a load is matched on against the stores in flight
# Offsets (bytes, modulo PAGE) of invm, A, d0, load, then the stored arrays u, v, f.
PAGE_OFFSETS = (0, 448, 896, 1344, 2048, 2816, 3584)


@jit
def page_slots(sizes):
    """(starts, total): where in a page-aligned workspace array k of sizes[k] float64s
    starts (elements), each after the one before at byte PAGE_OFFSETS[k] of a page, and the
    workspace's size (elements)."""
    starts = np.empty(sizes.shape[0], np.int64)
    end = 0
    for k in range(sizes.shape[0]):
        starts[k] = end + (PAGE_OFFSETS[k] // 8 - end) % (PAGE // 8)
        end = starts[k] + sizes[k]
    return starts, end


@jit
def workspace(n):
    """n float64s whose element 0 starts a 4 KiB page."""
    buf = np.empty(n + PAGE // 8)
    k = (-(buf.ctypes.data // 8)) % (PAGE // 8)
    return buf[k:k + n]


def working_arrays(*arrays: np.ndarray) -> list:
    """Copies of the float64 arrays invm, A, d0, load, u, v, f (in that order, any shapes)
    in one workspace, placed by page_slots (module doc)."""
    starts, total = page_slots(np.array([a.size for a in arrays], dtype=np.int64))
    ws = workspace(total)
    out = []
    for a, start in zip(arrays, starts):
        x = ws[start:start + a.size].reshape(a.shape)
        x[...] = a
        out.append(x)
    return out


@jit
def chunk_arrays(invm, A, d0, load, u, v):
    """working_arrays for one chunk of the batched kernel, arrays (bodies, width) (load
    (bodies + 1, width)), with f (bodies + 1, width) zeros: (invm, A, d0, load, u, v, f)."""
    nb, W = u.shape
    sizes = np.array([nb * W, nb * W, nb * W, (nb + 1) * W, nb * W, nb * W, (nb + 1) * W], dtype=np.int64)
    starts, total = page_slots(sizes)
    ws = workspace(total)
    invm_w = ws[starts[0]:starts[0] + sizes[0]].reshape((nb, W))
    A_w = ws[starts[1]:starts[1] + sizes[1]].reshape((nb, W))
    d0_w = ws[starts[2]:starts[2] + sizes[2]].reshape((nb, W))
    load_w = ws[starts[3]:starts[3] + sizes[3]].reshape((nb + 1, W))
    u_w = ws[starts[4]:starts[4] + sizes[4]].reshape((nb, W))
    v_w = ws[starts[5]:starts[5] + sizes[5]].reshape((nb, W))
    f_w = ws[starts[6]:starts[6] + sizes[6]].reshape((nb + 1, W))
    invm_w[:] = invm
    A_w[:] = A
    d0_w[:] = d0
    load_w[:] = load
    u_w[:] = u
    v_w[:] = v
    f_w[:] = 0.0
    return invm_w, A_w, d0_w, load_w, u_w, v_w, f_w
