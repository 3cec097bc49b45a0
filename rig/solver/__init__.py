"""How a chain is integrated: the problem's flat arrays, what to save (SaveAt), the method
registry, the step-size rule, solve and the batched ensemble solve, the Solution, and the
numba kernels (kernels/). Imports rig.model and the foundation."""
