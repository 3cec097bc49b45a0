"""The part of the solver's kernels a side process compiles on a cold numba cache
(instruments/precompile.py), while the command's own process compiles the rest.

The single-shot kernel (kernels/integrators.integrate) calls the multirate head's flow
(kernels/multirate.head_flow, with its resolved impacts the largest subtree it compiles)
after the contacts, the records and the dissipation: compiled aside, it is in the cache by
the time the main process gets there. Its arrays are (bodies, shots), as the batched
kernel's (kernels/ensemble.py), which then loads the same machine code.
"""
F1, F2, F4 = "float64[::1]", "float64[:, ::1]", "float64[:, :, :, ::1]"
SIDE = {"rig.solver.kernels.multirate.head_flow": f"({F2}, {F2}, {F2}, {F2}, {F2}, {F2}, {F2}, int64, {F1}, {F1}, "
                                                  f"float64, int64, {F4}, {F2})"}
