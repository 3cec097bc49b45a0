"""numba kernels of the benchmark's peer solvers: SI floats and flat float64 arrays only.

Body layout and state as in rig/solver/kernels/: ``nb`` bodies from the top (striker,
beads, wall of zero inverse mass), displacement ``u`` from static equilibrium (m) and
velocity ``v`` (m/s); a peer that integrates the first-order system holds them as one
state ``y = [u, v]`` (size 2 nb).
"""
from numerics.jit import drop_stale_cache

# the kernels inline hertz_forces (rig.solver.kernels.forces)
drop_stale_cache(__name__, constants=("rig.model.contact", "rig.solver.kernels.forces"))
