"""Long-wave theory against the published values, and the discrete wave's limits."""
import math

import pytest

from rig import hertz_constant, material
from rig.theory.longwave import solitary_wave_speed, sonic_vacuum_speed, sound_speed
from rig.theory.solitary import solitary_wave

D = 4.76e-3


@pytest.mark.parametrize("name,F0,published", [
    ("ptfe", 0.017, 92.6), ("ptfe", 2.397, 211.2), ("steel316", 0.062, 292.6), ("steel316", 2.44, 539.6)])
def test_sound_speed_reproduces_published_values(name, F0, published):
    m = material(name)
    assert sound_speed(m.E, m.nu, m.rho, D, F0) == pytest.approx(published, rel=1e-3)


def test_eq1_limits():
    m = material("ptfe")
    c0 = sound_speed(m.E, m.nu, m.rho, D, 2.397)
    assert solitary_wave_speed(m.E, m.nu, m.rho, D, 2.397, 2.397 * (1 + 1e-6)) == pytest.approx(c0, rel=1e-5)
    sv = sonic_vacuum_speed(m.E, m.nu, m.rho, D, 10.0)
    assert solitary_wave_speed(m.E, m.nu, m.rho, D, 1e-9, 10.0) == pytest.approx(sv, rel=1e-3)


def _steel_chain():
    m = material("steel316")
    return m, m.rho * math.pi * D**3 / 6, hertz_constant(m.E, m.nu, D / 2, m.E, m.nu, D / 2)


def test_discrete_sonic_vacuum_wave_is_about_one_percent_faster_than_eq4():
    m, mass, A = _steel_chain()
    for Fm in (1.0, 10.0, 100.0):
        w = solitary_wave(mass, A, D, Fm)
        ratio = w.speed / sonic_vacuum_speed(m.E, m.nu, m.rho, D, Fm)
        assert ratio == pytest.approx(1.01246, abs=2e-5)  # the same constant at every amplitude
        assert 3.0 < w.width_beads < 5.0  # compact: about five diameters, as theory says
    assert w.beta == pytest.approx(1.414, abs=2e-3)


@pytest.mark.parametrize("F0", [0.062, 2.44])
def test_precompressed_discrete_wave_approaches_eq1_and_beta_depends_on_fr_only(F0):
    m, mass, A = _steel_chain()
    weak = solitary_wave(mass, A, D, 1.1 * F0, F0)
    assert weak.speed == pytest.approx(solitary_wave_speed(m.E, m.nu, m.rho, D, F0, 1.1 * F0), rel=2e-4)
    strong = solitary_wave(mass, A, D, 50 * F0, F0)
    assert 1.0 < strong.speed / solitary_wave_speed(m.E, m.nu, m.rho, D, F0, 50 * F0) < 1.012
    # beta = F_d / F_m,e grows from 1 (long waves) towards the sonic-vacuum value
    assert 1.0 < weak.beta < strong.beta < solitary_wave(mass, A, D, 10.0).beta
    assert solitary_wave(mass, A * 0.01, D, 5 * F0 * 0.01, F0 * 0.01).beta == pytest.approx(
        solitary_wave(mass, A, D, 5 * F0, F0).beta, rel=1e-6)  # independent of the modulus


def test_beta_curve_from_the_discrete_chain():
    from rig.theory.solitary import beta
    curve = [beta(fr) for fr in (1.1, 2.0, 5.0, 50.0, float("inf"))]
    assert all(b2 > b1 for b1, b2 in zip(curve, curve[1:]))  # grows with F_m/F_0
    assert curve[0] == pytest.approx(1.008, abs=1e-3)  # long waves: gauge reads the contact
    assert curve[-1] == pytest.approx(1.414, abs=2e-3)  # sonic vacuum


@pytest.mark.parametrize("F0,Fm", [(0.062, 20.0), (0.0, 5.0)])
def test_the_discrete_wave_speed_scales_exactly_as_the_long_wave_one(F0, Fm):
    """At fixed forces a chain of diameter a has c0, Eq (1) and Eq (4) proportional to
    a^(-1/3); the discrete wave's beads per second times a scale the same way, so its ratio
    to Eq (4) is one number from 10 um to 10 cm (it had drifted from 1.0287 at 10 cm to
    0.98 at 0.1 mm and turned negative below, counted on the spacing a - overlap)."""
    m = material("ptfe")
    ratios = []
    for a in (1e-5, 1e-4, 3e-4, 4.76e-3, 1e-2, 1e-1):
        A = hertz_constant(m.E, m.nu, a / 2, m.E, m.nu, a / 2)
        wave = solitary_wave(m.rho * math.pi * a**3 / 6, A, a, Fm, F0)
        ratios.append(wave.long_wave_speed / sonic_vacuum_speed(m.E, m.nu, m.rho, a, Fm))
    assert max(ratios) - min(ratios) < 1e-3 * ratios[0], ratios
    assert 1.0 < ratios[0] < 1.04  # the discrete wave runs a little ahead of Eq (4)


def test_the_discrete_wave_is_solved_at_any_scale():
    """Solved in units of its own amplitude: the same wave at 1e-30 m and 1e30 m."""
    unit = solitary_wave(1.0, 1.0, 1.0, 3.0, 1.0)
    for k in (1e-30, 1e30):  # lengths times k, masses times k^3, forces times k^2: A times k^(1/2)
        wave = solitary_wave(k**3, k**0.5, k, 3.0 * k**2, k**2)
        assert wave.long_wave_speed == pytest.approx(unit.long_wave_speed, rel=1e-9)
        assert wave.beta == pytest.approx(unit.beta, rel=1e-9)


def test_eq1_at_force_ratios_that_overflow_a_power():
    """Eq (1) at F_m/F_0 = 1e600 is Eq (4), with no overflow on the way."""
    import warnings

    m = material("ptfe")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        v = solitary_wave_speed(m.E, m.nu, m.rho, D, 1e-300, 1e300)
    assert v == pytest.approx(sonic_vacuum_speed(m.E, m.nu, m.rho, D, 1e300), rel=1e-5)  # 0.9314 sqrt(8/15) = 0.6802
