"""Contact constants and the elastic law's forms (the laws themselves: rig.model.laws).

Hertz (e.g. Johnson, *Contact Mechanics*, 1985)::

    F = A * delta^(3/2)  (delta > 0),  0 otherwise
    A = (4/3) E_eff sqrt(R_eff),  1/E_eff = (1-nu1^2)/E1 + (1-nu2^2)/E2,  1/R_eff = 1/R1 + 1/R2
    elastic energy  U = (2/5) A delta^(5/2)

A flat face (striker, wall) has R = infinity, so R_eff is the sphere's radius.

A power law F = A_n delta^n, U = A_n delta^(n+1) / (n+1), describes a contact that departs
from Hertz's 3/2 (a polymer's modulus that depends on strain and strain rate, rough
surfaces): A_n is set so that it carries a reference force at the same overlap as the
Hertz contact of the same parts (``power_law_constant``), so that the exponent and the
modulus stay two separate parameters.
"""
from __future__ import annotations

import math

import numpy as np

from rig.errors import invalid
from rig.model import laws


def hertz_constant(E1: float, nu1: float, R1: float, E2: float, nu2: float,
                   R2: float = math.inf) -> float:
    """Hertz constant A (N/m^1.5) for two bodies of radii R1, R2 (m; inf for a flat)."""
    e_eff = 1.0 / ((1.0 - nu1**2) / E1 + (1.0 - nu2**2) / E2)
    curvature = (1.0 / R1 if math.isfinite(R1) else 0.0) + (1.0 / R2 if math.isfinite(R2) else 0.0)
    if curvature <= 0.0:
        raise invalid("contact", "flat on flat", "one of the two bodies must be a sphere")
    return 4.0 / 3.0 * e_eff * math.sqrt(1.0 / curvature)


def power_of(delta, n):
    """delta^n for delta > 0, else 0; n may be an array. The Hertz exponent takes
    delta sqrt(delta) and the linear one delta itself, the kernels' operations."""
    d = np.maximum(delta, 0.0)
    n = np.asarray(n, dtype=float)
    return np.where(n == 1.5, d * np.sqrt(d), np.where(n == 1.0, d, d ** n))


def hertz_force(A, delta, n=1.5):
    """F = A delta^n for delta > 0, else 0 (N): Hertz's law at n = 3/2 (A in N/m^n);
    works on floats and arrays."""
    if np.all(np.asarray(n) == 1.5):
        d = np.maximum(delta, 0.0)
        return A * d * np.sqrt(d)
    return A * power_of(delta, n)


def hertz_energy(A, delta, n=1.5):
    """U = A delta^(n+1) / (n+1) for delta > 0, else 0 (J): (2/5) A delta^(5/2) for Hertz."""
    if np.all(np.asarray(n) == 1.5):
        d = np.maximum(delta, 0.0)
        return 0.4 * A * d * d * np.sqrt(d)
    d = np.maximum(delta, 0.0)
    return A * d * power_of(d, n) / (np.asarray(n, dtype=float) + 1.0)


def static_overlaps(A, force, n=1.5):
    """Overlap (m) at which a contact A delta^n carries ``force`` (N): delta = (F/A)^(1/n)
    ((F/A)^(2/3) for Hertz)."""
    ratio = np.asarray(force, dtype=float) / A
    if np.all(np.asarray(n) == 1.5):
        return np.cbrt(ratio**2)
    n = np.asarray(n, dtype=float)
    with np.errstate(invalid="ignore"):
        return np.where(n == 1.5, np.cbrt(ratio**2), ratio ** (1.0 / n))


def contact_stiffness(A, force, n=1.5):
    """Tangent stiffness dF/ddelta = n A^(1/n) F^((n-1)/n) (N/m) at contact force F:
    (3/2) A^(2/3) F^(1/3) for Hertz."""
    if np.all(np.asarray(n) == 1.5):
        return 1.5 * np.cbrt(A**2 * np.asarray(force, dtype=float))
    n = np.asarray(n, dtype=float)
    A, force = np.asarray(A, dtype=float), np.asarray(force, dtype=float)
    with np.errstate(invalid="ignore"):
        return np.where(n == 1.5, 1.5 * np.cbrt(A**2 * force), n * A ** (1.0 / n) * force ** ((n - 1.0) / n))


def power_law_constant(A_hertz, n, reference_force):
    """The constant A_n (N/m^n) of a power law F = A_n delta^n that carries
    ``reference_force`` (N) at the overlap where the Hertz contact of constant A_hertz
    (N/m^1.5) does: delta_ref = (F_ref / A_hertz)^(2/3), A_n = F_ref / delta_ref^n. A_hertz
    itself for n = 3/2."""
    if n == 1.5:
        return A_hertz
    delta_ref = np.cbrt((reference_force / np.asarray(A_hertz, dtype=float)) ** 2)
    return reference_force / delta_ref**n


# The laws themselves (names, equations, parameters, kernel codes) live one module each in
# rig.model.laws; their registry is re-exported here, where the rig has always read it.
CONTACT_LAWS, HERTZ, KUWABARA_KONO, POWER, PLASTIC = (laws.CONTACT_LAWS, laws.HERTZ, laws.KUWABARA_KONO, laws.POWER,
                                                 laws.PLASTIC)
ContactLaw, contact_law = laws.ContactLaw, laws.contact_law
