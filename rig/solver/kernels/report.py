"""Where an integration kernel writes its report: the slots of its float64[DIAGNOSTICS]
diagnostics array (a batch's: one such column per shot), by name. The kernels write
``diag[ENERGY_ERROR] = ...`` and rig.solver.solution.KernelReport reads the same names;
numba reads these globals as compile-time constants (the package's cache guard covers
this file)."""

ENERGY_ERROR = 0  # largest |E(t) + dissipated(t) - E(0)| / E_ref over the checks
MOMENTUM_ERROR = 1  # largest |P(t) - P(0) - external impulse| / P_ref over the checks
WALL_IMPULSE = 2  # the wall's total impulse (N s)
STATUS = 3  # rig.solver.solution.Status: 0 the end time reached, 1 unstable
STEPS = 4  # steps done
END_TIME = 5  # the time reached (s)
DISSIPATED = 6  # the energy dissipation took, the contacts' plastic work included (J)
BODIES_STEPPED = 7  # bodies integrated, summed over the steps (the front)
DIAGNOSTICS = 8  # the floats of a kernel's diagnostics array
