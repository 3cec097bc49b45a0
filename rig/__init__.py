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

TYPE_CHECKING = False  # typing.TYPE_CHECKING without loading typing; mypy and pyright read the name
if TYPE_CHECKING:  # the names of _PUBLIC, for type checkers and editors (tests/test_typing.py holds them equal);
    # "X as X": re-exported, as a typed package's checkers read it
    from rig.errors import RigError as RigError
    from rig.model.apparatus import Holder as Holder
    from rig.model.chain import STANDARD_GRAVITY as STANDARD_GRAVITY
    from rig.model.chain import Chain as Chain
    from rig.model.chain import ForceSchedule as ForceSchedule
    from rig.model.chain import Probe as Probe
    from rig.model.contact import CONTACT_LAWS as CONTACT_LAWS
    from rig.model.contact import hertz_constant as hertz_constant
    from rig.model.contact import hertz_energy as hertz_energy
    from rig.model.contact import hertz_force as hertz_force
    from rig.model.contact import power_law_constant as power_law_constant
    from rig.model.contact import static_overlaps as static_overlaps
    from rig.model.materials import MATERIALS as MATERIALS
    from rig.model.materials import Material as Material
    from rig.model.materials import material as material
    from rig.model.parts import Bead as Bead
    from rig.model.parts import GaugeBead as GaugeBead
    from rig.model.parts import MagneticBead as MagneticBead
    from rig.model.parts import Striker as Striker
    from rig.model.parts import Wall as Wall
    from rig.solver.methods import METHODS as METHODS
    from rig.solver.methods import Method as Method
    from rig.solver.problem import ChainProblem as ChainProblem
    from rig.solver.saveat import SaveAt as SaveAt
    from rig.solver.solution import Solution as Solution
    from rig.solver.solution import SolverStats as SolverStats
    from rig.solver.solution import Status as Status
    from rig.solver.solve import solve as solve


def __getattr__(name: str):
    if name not in _WHERE:
        raise AttributeError(f"module 'rig' has no attribute {name!r}")
    value = getattr(importlib.import_module(_WHERE[name]), name)
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(__all__))
