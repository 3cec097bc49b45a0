"""The virtual rig: chain physics, the solver, the theory, the virtual experiment.

Quick use::

    from rig import Bead, MagneticBead, Striker, Wall, Chain, SaveAt, solve
    beads = [MagneticBead()] + [Bead("ptfe", "4.76 mm", "0.1226 g")] * 52
    chain = Chain(beads, striker=Striker("alumina", "0.47 g", "0.89 m/s"), wall=Wall(),
                  top_force="2.38 N")
    sol = solve(chain, t_end=2e-3, save=SaveAt({"wall": chain.wall_probe()}))

The names below are loaded on first use (PEP 562), so that ``import rig`` and the command
line start without numba, scipy or pint; docs/architecture.md shows the layers.
"""
from __future__ import annotations

import importlib

__version__ = "0.1.0"

_PUBLIC = {
    "rig.model.chain": ("Chain", "ForceSchedule", "Probe", "STANDARD_GRAVITY"),
    "rig.model.contact": ("CONTACT_LAWS", "hertz_constant", "hertz_energy", "hertz_force", "power_law_constant",
                          "static_overlaps"),
    "rig.model.apparatus": ("Holder",),
    "rig.model.materials": ("MATERIALS", "Material", "material"),
    "rig.model.parts": ("Bead", "GaugeBead", "MagneticBead", "Striker", "Wall"),
    "rig.errors": ("RigError",),
    "rig.solver.methods": ("METHODS", "Method"),
    "rig.solver.problem": ("ChainProblem",),
    "rig.solver.saveat": ("SaveAt",),
    "rig.solver.solution": ("Solution", "SolverStats", "Status"),
    "rig.solver.solve": ("solve",),
}
_WHERE = {name: module for module, names in _PUBLIC.items() for name in names}
__all__ = sorted(_WHERE)


def __getattr__(name: str):
    if name not in _WHERE:
        raise AttributeError(f"module 'rig' has no attribute {name!r}")
    value = getattr(importlib.import_module(_WHERE[name]), name)
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(__all__))
