"""The virtual rig: chain physics, the solver and the long-wave theory.

Quick use::

    from rig import Bead, MagneticBead, Striker, Wall, Chain, Record, solve
    beads = [MagneticBead()] + [Bead("ptfe", "4.76 mm", "0.1226 g")] * 52
    chain = Chain(beads, striker=Striker("alumina", "0.47 g", "0.89 m/s"), wall=Wall(),
                  top_force="2.38 N")
    sol = solve(chain.problem(Record({"wall": chain.wall_probe()})), t_end=2e-3)
"""
from .chain import Chain, ForceSchedule, Probe, Record, STANDARD_GRAVITY
from .contact import CONTACT_LAWS, hertz_constant, hertz_energy, hertz_force, static_overlaps
from .errors import RigError
from .materials import MATERIALS, Material, material
from .methods import METHODS, Method
from .parts import Bead, GaugeBead, MagneticBead, Striker, Wall
from .problem import ChainProblem
from .solution import Solution, SolverStats
from .solve import solve

__all__ = [
    "Bead", "GaugeBead", "MagneticBead", "Striker", "Wall", "Chain", "ForceSchedule",
    "Probe", "Record", "ChainProblem", "Solution", "SolverStats", "solve", "RigError",
    "MATERIALS", "Material", "material", "METHODS", "Method", "CONTACT_LAWS",
    "hertz_constant", "hertz_force", "hertz_energy", "static_overlaps", "STANDARD_GRAVITY",
]
__version__ = "0.1.0"
