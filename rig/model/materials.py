"""Material table of the published experiment (SI units), with sources.

Values from Daraio, Nesterenko, Herbold & Jin, Phys. Rev. E 73, 026610 (2006) unless the
``source`` says otherwise. Densities not given there are handbook values, used for part
geometry (a striker's length, a default bead mass) and never for the published masses.
"""
from __future__ import annotations

from dataclasses import dataclass

from rig.errors import invalid, lookup


@dataclass(frozen=True)
class Material:
    """An isotropic elastic material: E (Pa), Poisson ratio nu, density rho (kg/m^3)."""

    name: str
    E: float
    nu: float
    rho: float
    source: str

    def __post_init__(self):
        if not self.E > 0:
            raise invalid(f"material[{self.name}].E", self.E, "Young's modulus must be > 0 Pa")
        if not -1.0 < self.nu < 0.5:
            raise invalid(f"material[{self.name}].nu", self.nu, "Poisson ratio must lie in (-1, 0.5)")
        if not self.rho > 0:
            raise invalid(f"material[{self.name}].rho", self.rho, "density must be > 0 kg/m^3")


_PAPER = "Daraio et al., Phys. Rev. E 73, 026610 (2006)"

MATERIALS: dict[str, Material] = {
    m.name: m
    for m in (
        Material("ptfe", 1.46e9, 0.46, 2200.0, _PAPER + " (dynamic modulus)"),
        Material("steel316", 193e9, 0.30, 8000.0, _PAPER),
        Material("chrome_steel", 200e9, 0.30, 7830.0,
                 "assumed: the magnetic top bead's elastic constants are not published; "
                 "AISI 52100 chrome steel handbook values"),
        Material("alumina", 416e9, 0.231, 3900.0,
                 _PAPER + " (E, nu); density: handbook value for 99.5% Al2O3"),
        Material("brass", 115e9, 0.307, 8750.0,
                 _PAPER + " (red brass Cu85-Zn15 wall plate; density: handbook)"),
    )
}


def material(name) -> Material:
    """Look a material up by name (or pass a Material through)."""
    return lookup(MATERIALS, name, "material", Material)
