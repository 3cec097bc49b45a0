"""Contact laws between neighbours: the Hertz law and an optional dissipative variant.

Hertz (e.g. Johnson, *Contact Mechanics*, 1985)::

    F = A * delta^(3/2)  (delta > 0),  0 otherwise
    A = (4/3) E_eff sqrt(R_eff),  1/E_eff = (1-nu1^2)/E1 + (1-nu2^2)/E2,  1/R_eff = 1/R1 + 1/R2
    elastic energy  U = (2/5) A delta^(5/2)

A flat face (striker, wall) has R = infinity, so R_eff is the sphere's radius.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rig.errors import invalid, lookup
from rig.model.materials import Material


def hertz_constant(E1: float, nu1: float, R1: float, E2: float, nu2: float,
                   R2: float = math.inf) -> float:
    """Hertz constant A (N/m^1.5) for two bodies of radii R1, R2 (m; inf for a flat)."""
    e_eff = 1.0 / ((1.0 - nu1**2) / E1 + (1.0 - nu2**2) / E2)
    curvature = (1.0 / R1 if math.isfinite(R1) else 0.0) + (1.0 / R2 if math.isfinite(R2) else 0.0)
    if curvature <= 0.0:
        raise invalid("contact", "flat on flat", "one of the two bodies must be a sphere")
    return 4.0 / 3.0 * e_eff * math.sqrt(1.0 / curvature)


def contact_constant(m1: Material, R1: float, m2: Material, R2: float = math.inf) -> float:
    """Hertz constant between two parts made of materials m1, m2 (radii in m, inf = flat)."""
    return hertz_constant(m1.E, m1.nu, R1, m2.E, m2.nu, R2)


def hertz_force(A, delta):
    """F = A delta^(3/2) for delta > 0, else 0 (N); works on floats and arrays."""
    d = np.maximum(delta, 0.0)
    return A * d * np.sqrt(d)


def hertz_energy(A, delta):
    """U = (2/5) A delta^(5/2) for delta > 0, else 0 (J)."""
    d = np.maximum(delta, 0.0)
    return 0.4 * A * d * d * np.sqrt(d)


def static_overlaps(A, force):
    """Overlap (m) at which a Hertz contact carries ``force`` (N): delta = (F/A)^(2/3)."""
    return np.cbrt((np.asarray(force, dtype=float) / A) ** 2)


def contact_stiffness(A, force):
    """Tangent stiffness dF/ddelta = (3/2) A^(2/3) F^(1/3) (N/m) at contact force F."""
    return 1.5 * np.cbrt(A**2 * np.asarray(force, dtype=float))


HERTZ = 0          # the kernels' code of each law: the one source (rig/solver/kernels/forces.py)
KUWABARA_KONO = 1


@dataclass(frozen=True)
class ContactLaw:
    """A contact law the kernels know by ``code``; ``damping_time`` (s) only where used."""

    name: str
    code: int
    description: str
    dissipative: bool


CONTACT_LAWS: dict[str, ContactLaw] = {
    law.name: law
    for law in (
        ContactLaw("hertz", HERTZ, "elastic Hertz law F = A delta^(3/2) (conservative)", False),
        ContactLaw(
            "kuwabara-kono", KUWABARA_KONO,
            "viscoelastic Hertz law F = A delta^(1/2) (delta + tau_d d(delta)/dt), never "
            "attractive (Kuwabara & Kono, Jpn. J. Appl. Phys. 26, 1230 (1987); Brilliantov "
            "et al., Phys. Rev. E 53, 5382 (1996)); tau_d is the material's damping time",
            True),
    )
}


def contact_law(name) -> ContactLaw:
    """Look a contact law up by name."""
    return lookup(CONTACT_LAWS, name, "contact_law", ContactLaw)
