"""Long-wave and discrete solitary waves for a power-law contact F = A delta^n."""
import math

import numpy as np
import pytest
from scipy.integrate import quad

from rig import hertz_constant, material
from rig.theory.longwave import (
    power_law_sound_speed,
    power_law_wave_speed,
    solitary_wave_speed,
    sonic_vacuum_speed,
    sound_speed,
)
from rig.theory.solitary import beta, solitary_wave

D = 4.76e-3
MASS = 4.5e-4
# Eq (2) with A = E sqrt(a) / (3 (1 - nu^2)) (hertz_constant for two spheres of radius a/2)
# and mass = rho pi a^3 / 6 has the coefficient sqrt(9/pi) / 6^(1/3) = 0.931456..., which
# Daraio et al. print as 0.9314 (Eqs 1, 2) and, times sqrt(8/15), as 0.6802 (Eq 4).
EQ2 = math.sqrt(9 / math.pi) / 6 ** (1 / 3)


def _A(n):
    """A (N/m^n) giving 1 N at an overlap of 1 um, so that every n sees similar strains."""
    return 1.0 / 1e-6**n


def _steel_hertz():
    m = material("steel316")
    return m, m.rho * math.pi * D**3 / 6, hertz_constant(m.E, m.nu, D / 2, m.E, m.nu, D / 2)


def test_n_three_halves_is_the_hertz_theory():
    m, mass, A = _steel_hertz()
    F0 = np.array([0.017, 0.062, 2.44, 2.44, 2.44])
    Fm = np.array([0.02, 20.0, 2.45, 10.0, 1e3])
    V = power_law_wave_speed(A, 1.5, mass, D, F0, Fm)
    eq1 = solitary_wave_speed(m.E, m.nu, m.rho, D, F0, Fm)
    np.testing.assert_allclose(V, eq1 * EQ2 / 0.9314, rtol=1e-12, atol=0)
    assert np.all(abs(V / eq1 - 1) < 1e-4)  # the printed coefficient's rounding, 6e-5
    c0 = power_law_sound_speed(A, 1.5, mass, D, F0)
    np.testing.assert_allclose(c0, sound_speed(m.E, m.nu, m.rho, D, F0) * EQ2 / 0.9314, rtol=1e-12, atol=0)
    sv = power_law_wave_speed(A, 1.5, mass, D, 0.0, Fm)
    eq4 = sonic_vacuum_speed(m.E, m.nu, m.rho, D, Fm)
    np.testing.assert_allclose(sv, eq4 * EQ2 * math.sqrt(8 / 15) / 0.6802, rtol=1e-12, atol=0)


@pytest.mark.parametrize("n", [1.0, 1.2, 1.5, 1.75, 2.0, 2.5, 3.0])
def test_wave_speed_is_free_of_cancellation(n):
    A, F0 = _A(n), 0.3
    c0 = power_law_sound_speed(A, n, MASS, D, F0)
    assert power_law_wave_speed(A, n, MASS, D, F0, F0) == pytest.approx(c0, rel=1e-14)
    # V^2 - c0^2 = c0^2 (n - 1) u / 3 + O(u^2), u = (xim - xi0) / xi0 = (1 + 1e-9)^(1/n) - 1
    tiny = power_law_wave_speed(A, n, MASS, D, F0, F0 * (1 + 1e-9))
    assert tiny == pytest.approx(c0, rel=2e-10)
    assert tiny / c0 - 1 == pytest.approx((n - 1) / 6 * 1e-9 / n, abs=1e-15)
    xi0 = (F0 / A) ** (1 / n) / D
    for u in (1e-12, 1e-6, 1e-3, 0.1, 0.4999, 0.5, 0.5001, 1.0, 10.0, 1e3):
        Fm = A * (xi0 * (1 + u) * D) ** n
        u = ((Fm / A) ** (1 / n) / D - xi0) / xi0  # the strain Fm rounds to
        # the bracket 2 int_xi0^xim (s^n - xi0^n) ds by quadrature, over xi0^(n+1) u^2
        g = 2 / u * quad(lambda t, u=u: np.expm1(n * np.log1p(u * t)), 0, 1, epsabs=0, epsrel=2e-14)[0]
        exact = math.sqrt(A * D ** (n + 1) / MASS * xi0 ** (n - 1) * g)
        assert power_law_wave_speed(A, n, MASS, D, F0, Fm) == pytest.approx(exact, rel=2e-14)


@pytest.mark.parametrize("n", [1.0, 1.5, 1.75, 2.5, 3.0])
def test_sonic_vacuum_closed_form(n):
    A, Fm = _A(n), np.array([0.0, 1e-3, 1.0, 50.0])
    c = math.sqrt(A * D ** (n + 1) / MASS)
    xim = (Fm / A) ** (1 / n) / D
    V = power_law_wave_speed(A, n, MASS, D, 0.0, Fm)
    np.testing.assert_allclose(V, c * math.sqrt(2 / (n + 1)) * xim ** ((n - 1) / 2), rtol=1e-14, atol=0)
    if n == 1.0:  # a linear chain: every wave travels at c = a sqrt(A / mass)
        assert np.all(pytest.approx(power_law_sound_speed(A, n, MASS, D, 0.0), rel=1e-15) == V)


def test_n_three_halves_solitary_wave_is_bit_identical_to_the_default():
    A = _A(1.5)
    for Fm, F0 in ((10.0, 0.0), (2.0, 1.0), (1.1, 1.0)):
        default, explicit = solitary_wave(MASS, A, D, Fm, F0), solitary_wave(MASS, A, D, Fm, F0, n=1.5)
        assert default.speed == explicit.speed and default.contacts_per_s == explicit.contacts_per_s
        assert np.array_equal(default.force, explicit.force) and np.array_equal(default.xi, explicit.xi)
    assert beta(2.0) == beta(2.0, n=1.5)


@pytest.mark.parametrize("n", [1.5, 1.75, 2.5])
@pytest.mark.parametrize("fr", [1.1, 1.2])
def test_discrete_wave_approaches_the_long_wave_speed(n, fr):
    """The long-wave theory keeps the chain's dispersion v/c0 = sinh(ka/2) / (ka/2) (k = i kappa
    on the wave's tails) to (ka)^2 / 24 only. Its speed excess eps = V/c0 - 1 fixes
    (ka)^2 = 24 eps; the term it drops, (ka)^4 / 1920, puts the discrete wave ahead by
    24^2 eps^2 / 1920 = 0.3 eps^2, up to O(f_r - 1). Speeds are compared in beads per
    second times a, as the long-wave theory counts them (solitary_wave's m/s use the
    compressed spacing a - delta0)."""
    A, F0 = _A(n), 0.5
    wave = solitary_wave(MASS, A, D, fr * F0, F0, n=n)
    V = power_law_wave_speed(A, n, MASS, D, F0, fr * F0)
    eps = V / power_law_sound_speed(A, n, MASS, D, F0) - 1
    gap = wave.contacts_per_s * D / V - 1
    assert abs(gap / (0.3 * eps**2) - 1) < fr - 1  # measured 4.0-4.3% at 1.1, 7.5-8.1% at 1.2
    assert 1.0 < wave.beta < beta(float("inf"), n=n)


@pytest.mark.parametrize("call,name", [
    (lambda: power_law_wave_speed(1.0, 0.5, 1.0, 1.0, 0.0, 1.0), "n"),
    (lambda: power_law_wave_speed(1.0, 3.5, 1.0, 1.0, 0.0, 1.0), "n"),
    (lambda: power_law_wave_speed(0.0, 1.5, 1.0, 1.0, 0.0, 1.0), "A"),
    (lambda: power_law_wave_speed(1.0, 1.5, -1.0, 1.0, 0.0, 1.0), "mass"),
    (lambda: power_law_wave_speed(1.0, 1.5, 1.0, 0.0, 0.0, 1.0), "a"),
    (lambda: power_law_wave_speed(1.0, 1.5, 1.0, 1.0, -1.0, 1.0), "F0"),
    (lambda: power_law_wave_speed(1.0, 1.5, 1.0, 1.0, [1.0, 2.0], [1.5, 1.5]), "Fm"),
    (lambda: power_law_sound_speed(1.0, float("nan"), 1.0, 1.0, 1.0), "n"),
    (lambda: power_law_sound_speed(1.0, 1.5, 1.0, 1.0, -1.0), "F0"),
    (lambda: solitary_wave(1.0, 1.0, 1.0, 1.0, n=1.0), "n"),
    (lambda: solitary_wave(1.0, 1.0, 1.0, 1.0, n=3.5), "n"),
    (lambda: beta(2.0, n=0.9), "n"),
])
def test_bad_inputs_name_the_argument(call, name):
    with pytest.raises(ValueError, match=rf"^{name} = .*: "):
        call()
