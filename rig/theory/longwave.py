"""Long-wave (continuum) theory of the granular chain, Nesterenko (2001).

Symbols: E Young's modulus (Pa), nu Poisson ratio, rho density (kg/m^3), a bead diameter
(m), F0 precompression (N), Fm maximum contact force (N), f_r = Fm / F0. Equation numbers
are those of Daraio et al., Phys. Rev. E 73, 026610 (2006) (PHYSICS.md section 4).
"""
from __future__ import annotations

import numpy as np

from rig.errors import invalid


def _stiffness_group(E, nu, rho, a):
    """(2E / (a rho^(3/2) (1 - nu^2)))^(1/3), the common factor of Eqs (2) and (4)."""
    return (2.0 * E / (a * rho**1.5 * (1.0 - nu**2))) ** (1.0 / 3.0)


def sound_speed(E, nu, rho, a, F0):
    """Eq (2): c0 = 0.9314 (2E / (a rho^(3/2) (1-nu^2)))^(1/3) F0^(1/6) (m/s)."""
    if np.any(np.asarray(F0) < 0):
        raise invalid("F0", F0, "precompression must be >= 0 N")
    return 0.9314 * _stiffness_group(E, nu, rho, a) * np.asarray(F0, dtype=float) ** (1.0 / 6.0)


def sonic_vacuum_speed(E, nu, rho, a, Fm):
    """Eq (4): V_s = 0.6802 (2E / (a rho^(3/2) (1-nu^2)))^(1/3) Fm^(1/6) (m/s), F0 -> 0."""
    if np.any(np.asarray(Fm) <= 0):
        raise invalid("Fm", Fm, "maximum force must be > 0 N")
    return 0.6802 * _stiffness_group(E, nu, rho, a) * np.asarray(Fm, dtype=float) ** (1.0 / 6.0)


def solitary_wave_speed(E, nu, rho, a, F0, Fm):
    """Eq (1): solitary wave speed (m/s) on a chain precompressed by F0 (N), amplitude Fm (N).

    V_s = 0.9314 (4 E^2 F0 / (a^2 rho^3 (1-nu^2)^2))^(1/6) / (f_r^(2/3) - 1)
          * sqrt((4/15) (3 + 2 f_r^(5/3) - 5 f_r^(2/3))),  f_r = Fm / F0.
    Tends to Eq (2) as f_r -> 1 and to Eq (4) as f_r -> infinity. Requires Fm > F0 > 0.
    Evaluated in the cancellation-free form with x = f_r^(1/3), using
    3 + 2x^5 - 5x^2 = (x-1)^2 (2x^3 + 4x^2 + 6x + 3) and x^2 - 1 = (x-1)(x+1):
    V_s = pre * sqrt((4/15) (2x^3 + 4x^2 + 6x + 3)) / (x + 1).
    """
    F0 = np.asarray(F0, dtype=float)
    Fm = np.asarray(Fm, dtype=float)
    if np.any(F0 <= 0):
        raise invalid("F0", F0, "Eq (1) needs a precompression > 0 N (use Eq (4) for F0 = 0)")
    if np.any(Fm <= F0):
        raise invalid("Fm", Fm, "the maximum force must exceed the precompression F0")
    fr = Fm / F0
    pre = 0.9314 * (4.0 * E**2 * F0 / (a**2 * rho**3 * (1.0 - nu**2) ** 2)) ** (1.0 / 6.0)
    x = np.cbrt(fr)
    return pre * np.sqrt(4.0 / 15.0 * (((2.0 * x + 4.0) * x + 6.0) * x + 3.0)) / (x + 1.0)
