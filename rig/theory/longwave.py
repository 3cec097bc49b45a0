"""Long-wave (continuum) theory of the granular chain, Nesterenko (2001).

Symbols: E Young's modulus (Pa), nu Poisson ratio, rho density (kg/m^3), a bead diameter
(m), F0 precompression (N), Fm maximum contact force (N), f_r = Fm / F0. Equation numbers
are those of Daraio et al., Phys. Rev. E 73, 026610 (2006) (PHYSICS.md section 4).
power_law_sound_speed and power_law_wave_speed give the same theory for a contact
F = A delta^n of any exponent 1 <= n <= 3 (Hertz: n = 3/2).
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
    V_s = pre * sqrt((4/15) (2x^3 + 4x^2 + 6x + 3)) / (x + 1), written with y = 1/x in (0, 1),
    which overflows at no f_r: V_s = 0.9314 S Fm^(1/6) sqrt((4/15) (2 + 4y + 6y^2 + 3y^3)) / (1 + y),
    S the stiffness group of Eqs (2) and (4).
    """
    F0 = np.asarray(F0, dtype=float)
    Fm = np.asarray(Fm, dtype=float)
    if np.any(F0 <= 0):
        raise invalid("F0", F0, "Eq (1) needs a precompression > 0 N (use Eq (4) for F0 = 0)")
    if np.any(Fm <= F0):
        raise invalid("Fm", Fm, "the maximum force must exceed the precompression F0")
    y = np.cbrt(F0 / Fm)
    pre = 0.9314 * _stiffness_group(E, nu, rho, a) * Fm ** (1.0 / 6.0)
    return pre * np.sqrt(4.0 / 15.0 * (((3.0 * y + 6.0) * y + 4.0) * y + 2.0)) / (1.0 + y)


# Power-law contact F = A delta^n (Hertz: n = 3/2), Nesterenko, Dynamics of Heterogeneous
# Materials (2001), ch. 1. Symbols: A contact constant (N/m^n), mass bead mass (kg), a bead
# diameter = unstrained centre spacing (m), strains xi = delta / a, c^2 = A a^(n+1) / mass.
# Speeds are in m/s of the Lagrangian coordinate (a per bead).

_SERIES_BELOW = 0.5  # (xim - xi0) / xi0 below which the bracket is summed as a series
_SERIES_TERMS = 60  # 0.5^60 < 1e-18 and |binom(n, j)| <= 3 for n in [1, 3]


def _check_power_law(A, n, mass, a, F0, Fm):
    """Validate the power-law chain; return n as a float and F0, Fm as float arrays."""
    if not 1.0 <= n <= 3.0:
        raise invalid("n", n, "the contact exponent must be in [1, 3]")
    for name, val in (("A", A), ("mass", mass), ("a", a)):
        if not val > 0:
            raise invalid(name, val, "must be > 0")
    F0 = np.asarray(F0, dtype=float)
    Fm = np.asarray(Fm, dtype=float)
    if not np.all(F0 >= 0):
        raise invalid("F0", F0, "precompression must be >= 0 N")
    if not np.all(Fm >= F0):
        raise invalid("Fm", Fm, "the maximum force must be >= the precompression F0")
    return float(n), F0, Fm


def _g_series(n, u):
    """g(u) = 2 sum_{j=1..} binom(n, j) u^(j-1) / (j + 1) for 0 <= u <= 1/2, by Horner."""
    coefs, binom = [], n
    for j in range(1, _SERIES_TERMS + 1):
        coefs.append(2.0 * binom / (j + 1))
        binom *= (n - j) / (j + 1)
    g = np.zeros_like(u)
    for c in reversed(coefs):
        g = g * u + c
    return g


def power_law_sound_speed(A, n, mass, a, F0):
    """Sound speed c0 = a sqrt(k / mass) (m/s) of a chain precompressed by F0 (N).

    k = n A delta0^(n-1) (N/m) is the contact's tangent stiffness at delta0 = (F0/A)^(1/n).
    For n = 3/2 and A the Hertz constant of two identical spheres this is Eq (2).
    """
    n, F0, _ = _check_power_law(A, n, mass, a, F0, F0)
    delta0 = (F0 / A) ** (1.0 / n)
    return a * np.sqrt(n * A * delta0 ** (n - 1.0) / mass)


def power_law_wave_speed(A, n, mass, a, F0, Fm):
    """Long-wave solitary wave speed V (m/s), precompression F0 (N), maximum force Fm (N).

    V^2 = c^2 [(2/(n+1)) (xim^(n+1) - xi0^(n+1)) - 2 xi0^n (xim - xi0)] / (xim - xi0)^2,
    c^2 = A a^(n+1) / mass, xi0 = (F0/A)^(1/n) / a, xim = (Fm/A)^(1/n) / a.
    The bracket is 2 int_xi0^xim (s^n - xi0^n) ds. For u = (xim - xi0)/xi0 < 1/2 it is
    summed as xi0^(n+1) u^2 g(u), g(u) = 2 sum_j>=1 binom(n, j) u^(j-1) / (j + 1), which
    is free of cancellation and gives the sound speed at Fm = F0 (g(0) = n). F0 = 0 gives
    the sonic vacuum, V = c sqrt(2/(n+1)) xim^((n-1)/2). For n = 3/2 and A the Hertz
    constant of two identical spheres it is Eq (1) (Eq (4) at F0 = 0).
    """
    n, F0, Fm = _check_power_law(A, n, mass, a, F0, Fm)
    xi0 = (F0 / A) ** (1.0 / n) / a
    xim = (Fm / A) ** (1.0 / n) / a
    d = xim - xi0
    small = d <= _SERIES_BELOW * xi0  # includes Fm = F0 = 0
    u = np.divide(d, xi0, out=np.zeros_like(d), where=small & (xi0 > 0))
    series = xi0 ** (n - 1.0) * _g_series(n, u)
    d = np.where(small, 1.0, d)  # the direct form is kept only where d > xi0 / 2 >= 0
    direct = (2.0 / (n + 1.0) * (xim ** (n + 1.0) - xi0 ** (n + 1.0)) - 2.0 * xi0**n * d) / d**2
    return np.sqrt(A * a ** (n + 1.0) / mass * np.where(small, series, direct))
