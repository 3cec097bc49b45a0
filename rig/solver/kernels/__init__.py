"""numba kernels: SI floats and flat float64 arrays only, no Python objects.

Body layout shared by every kernel: ``nb`` bodies from the top (the striker if any, the
beads, then the wall as a body of zero inverse mass if any). ``u`` is the displacement
from static equilibrium (m, positive down), ``v`` the velocity (m/s). Force slot ``f[i]``
(size nb + 1) holds the contact between body i-1 and body i; ``f[0]`` and ``f[nb]`` stay 0
so that every body sees ``f[i] - f[i+1]`` with no special case at the ends.

The contact laws' kernel functions (rig.model.laws, marked ``numerics.jit.kernel``) are
compiled here, before any kernel of this package imports them.
"""
from numerics.jit import compile_kernels, drop_stale_cache
from rig.model import laws

for _module in laws.MODULES:
    compile_kernels(_module)
drop_stale_cache(__name__, constants=("rig.model.contact",) + tuple(m.__name__ for m in laws.MODULES)
                 + ("rig.model.laws.law",))
