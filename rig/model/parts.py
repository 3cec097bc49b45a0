"""The chain's parts: beads, gauge beads, the magnetic top bead, the striker, the wall.

Every length, mass and speed may be given as an SI float or as a string with its unit
("4.76 mm", "0.1226 g", "0.89 m/s"); strings are converted to SI once, on construction,
and every field is validated there (a RigError names the field and the allowed range).
"""
from __future__ import annotations

import functools
import math
from dataclasses import dataclass, fields
from typing import TYPE_CHECKING

from rig.errors import invalid
from rig.model.materials import Material, material
from rig.units import Quantity, is_real, quantity

# Published PTFE gauge bead (Daraio et al. 2006): caps 0.093 g, plate 0.023 g, of a 0.1226 g bead.
PTFE_GAUGE_CAPS_FRACTION = 0.093 / 0.1226
PZT_PLATE_MASS = 0.023e-3  # kg, 0.5 mm x 3 mm x 3 mm lead zirconate titanate with electrodes

_UNITS = {"diameter": "m", "mass": "kg", "caps_mass": "kg", "plate_mass": "kg",
          "velocity": "m/s", "gap": "m", "rod_stiffness": "N/m"}


@functools.cache
def _unit_fields(cls) -> tuple:
    """The fields of a part class that carry a unit."""
    return tuple(f.name for f in fields(cls) if f.name in _UNITS)


class _Part:
    """Shared construction: look the material up, convert quantities, validate."""

    material: Material | str

    def _convert(self, prefix: str):
        if not isinstance(self.material, Material):
            object.__setattr__(self, "material", material(self.material))
        # a class is hashable: typeshed's Hashable check trips on a dataclass's __hash__
        for name in _unit_fields(type(self)):  # type: ignore[arg-type]
            value = getattr(self, name)
            if value is None:
                continue
            if type(value) is float and math.isfinite(value):  # SI already (studies build many parts)
                continue
            object.__setattr__(self, name, quantity(value, _UNITS[name], f"{prefix}.{name}", bare_ok=True))

    def _positive(self, prefix: str, *names):
        for name in names:
            value = getattr(self, name)
            if not (is_real(value) and value > 0):
                raise invalid(f"{prefix}.{name}", value, f"must be > 0 {_UNITS[name]}")


MASS_FACTOR = 10.0
"""How far a bead's mass may lie from its solid sphere's, density x pi d^3 / 6: real beads
differ from it by a few percent (the published PTFE 0.1226 g against 0.1242 g, a gauge bead
0.116 g), a hollow or composite one (or a test's light steel bead) by a few times, a mass
in grams given as kilograms (or milligrams as grams) by a factor 1000."""


def sphere_mass(of: Material | str, diameter: float) -> float:
    """The mass (kg) of a solid sphere of the material ``of`` and ``diameter`` (m): rho pi d^3 / 6."""
    return material(of).rho * math.pi * diameter**3 / 6.0


def solid_sphere_check(field: str, mass: float, of: Material | str, diameter: float) -> None:
    """RigError in one line unless ``mass`` (kg) lies within MASS_FACTOR of a solid sphere of
    the material ``of`` and ``diameter`` (m), naming the field, the mass, the sphere's mass
    and the density it comes from."""
    m = material(of)
    sphere = sphere_mass(m, diameter)
    if not sphere / MASS_FACTOR <= mass <= sphere * MASS_FACTOR:
        raise invalid(field, mass, f"a {m.name} sphere of {diameter * 1e3:.4g} mm weighs "
                                  f"{sphere * 1e3:.4g} g (density {m.rho:g} kg/m^3); a bead's mass must lie "
                                  f"within a factor {MASS_FACTOR:g} of it (grams meant? give the unit, "
                                  f"'{mass:g} g')")


@dataclass(frozen=True)
class Bead(_Part):
    """A sphere of ``material``; ``mass`` defaults to density x volume (kg)."""

    material: Material | str
    diameter: float
    mass: float | None = None

    if TYPE_CHECKING:  # what the constructor takes (a quantity with its unit); the fields hold SI floats
        def __init__(self, material: Material | str, diameter: Quantity, mass: Quantity | None = None) -> None: ...

    def __post_init__(self):
        self._convert("bead")
        self._positive("bead", "diameter")
        if self.mass is None:
            object.__setattr__(self, "mass", sphere_mass(self.material, self.diameter))
        self._positive("bead", "mass")
        assert self.mass is not None, "just checked > 0"
        solid_sphere_check("bead.mass", self.mass, self.material, self.diameter)

    @property
    def radius(self) -> float:
        return 0.5 * self.diameter

    def with_mass(self, mass: float) -> Bead:
        """This bead with another mass (kg, > 0), its other fields taken as they are (already
        converted and checked): the bead-to-bead scatter of a study builds many."""
        if not (isinstance(mass, float) and math.isfinite(mass) and mass > 0):
            raise invalid("bead.mass", mass, "must be > 0 kg")
        bead = object.__new__(type(self))
        bead.__dict__.update(self.__dict__)
        object.__setattr__(bead, "mass", mass)
        return bead

    kind = "bead"


@dataclass(frozen=True)
class MagneticBead(Bead):
    """The magnetic steel ball on top of the chain that the ring magnet pulls (5 mm, 0.5 g)."""

    material: Material | str = "chrome_steel"
    diameter: float = 5e-3
    mass: float | None = 0.5e-3
    kind = "magnetic"

    if TYPE_CHECKING:  # what the constructor takes (a quantity with its unit); the fields hold SI floats
        def __init__(self, material: Material | str = "chrome_steel", diameter: Quantity = 5e-3,
                     mass: Quantity | None = 0.5e-3) -> None: ...


@dataclass(frozen=True)
class GaugeBead(Bead):
    """A bead cut in two with a piezo plate glued between its caps.

    Treated as rigid: its plate reads the mean of its two contact forces. Its mass is
    caps + plate. By default the caps keep the published PTFE fraction (0.093 g of a
    0.1226 g bead) of the plain bead's mass, and the plate weighs 0.023 g; for PTFE that
    gives the published 0.116 g.
    """

    caps_mass: float | None = None
    plate_mass: float | None = PZT_PLATE_MASS
    kind = "gauge"

    if TYPE_CHECKING:  # what the constructor takes (a quantity with its unit); the fields hold SI floats
        def __init__(self, material: Material | str, diameter: Quantity, mass: Quantity | None = None,
                     caps_mass: Quantity | None = None, plate_mass: Quantity | None = PZT_PLATE_MASS) -> None: ...

    def __post_init__(self):
        self._convert("gauge_bead")
        self._positive("gauge_bead", "diameter", "plate_mass")
        if self.caps_mass is None:
            plain = self.mass if self.mass is not None else sphere_mass(self.material, self.diameter)
            object.__setattr__(self, "caps_mass", self.caps_of(plain))
        self._positive("gauge_bead", "caps_mass")
        caps, plate = self.caps_mass, self.plate_mass
        assert caps is not None and plate is not None, "both were just checked > 0"
        object.__setattr__(self, "mass", caps + plate)

    @staticmethod
    def caps_of(plain_mass):
        """The caps' mass (kg) cut from a plain bead of ``plain_mass`` (kg; floats or arrays)."""
        return PTFE_GAUGE_CAPS_FRACTION * plain_mass

    @classmethod
    def like(cls, bead: Bead, mass: float | None = None) -> GaugeBead:
        """The gauge version of a plain bead (same material, diameter): caps cut from its
        mass and the plate, or the whole gauge bead's ``mass`` (kg) when given (the plate
        keeps its mass, the caps take the rest)."""
        if mass is None:
            return cls(bead.material, bead.diameter, mass=bead.mass)
        if not mass > PZT_PLATE_MASS:
            raise invalid("gauges.mass", mass, f"a gauge bead weighs more than its plate ({PZT_PLATE_MASS} kg)")
        solid_sphere_check("gauges.mass", mass, bead.material, bead.diameter)
        return cls(bead.material, bead.diameter, caps_mass=mass - PZT_PLATE_MASS)


MIN_STRIKER_VELOCITY = 1e-6  # m/s: at 1e-9 the energy error was 3.6e4 kinetic energies; 1e-300 squared to 0 J


@dataclass(frozen=True)
class Striker(_Part):
    """A cylinder dropped flat face first on the top bead with ``velocity`` (m/s, > 0).

    gap (m, >= 0): distance from its face to the top bead at t = 0 (0: impact at t = 0).
    """

    material: Material | str = "alumina"
    mass: float = 0.47e-3
    velocity: float = 0.89
    diameter: float = 4.76e-3
    gap: float = 0.0
    kind = "striker"

    if TYPE_CHECKING:  # what the constructor takes (a quantity with its unit); the fields hold SI floats
        def __init__(self, material: Material | str = "alumina", mass: Quantity = 0.47e-3, velocity: Quantity = 0.89,
                     diameter: Quantity = 4.76e-3, gap: Quantity = 0.0) -> None: ...

    def __post_init__(self):
        self._convert("striker")
        self._positive("striker", "mass", "velocity", "diameter")
        if self.velocity < MIN_STRIKER_VELOCITY:
            raise invalid("striker.velocity", f"{self.velocity:g} m/s",
                          f"at least {MIN_STRIKER_VELOCITY:g} m/s: slower, the striker's kinetic energy drowns in the "
                          "rounding of the chain's static energy")
        if not self.gap >= 0:
            raise invalid("striker.gap", self.gap,
                          "the striker would overlap the top bead; allowed: gap >= 0 m")

    @property
    def length(self) -> float:
        """Cylinder length (m) from mass, density and diameter."""
        return self.mass / (material(self.material).rho * math.pi * self.diameter**2 / 4.0)


@dataclass(frozen=True)
class Wall(_Part):
    """The bottom wall: the force sensor's top plate.

    Rigid by default. With ``plate_mass`` (kg) and ``rod_stiffness`` (N/m) both given it
    is a plate of that mass resting on a rod of that axial stiffness (the sensor plate on
    its steel rod): the plate moves, the last bead presses on it by the chain's contact
    law and the rod carries it by a linear spring F = k delta, whose force is what the
    wall sensor reads.
    """

    material: Material | str = "brass"
    plate_mass: float | None = None
    rod_stiffness: float | None = None
    kind = "wall"

    if TYPE_CHECKING:  # what the constructor takes (a quantity with its unit); the fields hold SI floats
        def __init__(self, material: Material | str = "brass", plate_mass: Quantity | None = None,
                     rod_stiffness: Quantity | None = None) -> None: ...

    def __post_init__(self):
        self._convert("wall")
        if (self.plate_mass is None) != (self.rod_stiffness is None):
            given = "plate_mass" if self.rod_stiffness is None else "rod_stiffness"
            raise invalid(f"wall.{given}", getattr(self, given),
                          "a compliant wall needs both plate_mass and rod_stiffness (or neither: rigid)")
        if self.compliant:
            self._positive("wall", "plate_mass", "rod_stiffness")

    @property
    def compliant(self) -> bool:
        return self.plate_mass is not None
