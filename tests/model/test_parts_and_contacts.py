"""Materials, parts, units and contact laws."""
import math

import pytest

from rig import (
    Bead,
    GaugeBead,
    MagneticBead,
    RigError,
    Striker,
    Wall,
    hertz_constant,
    hertz_energy,
    hertz_force,
    material,
    static_overlaps,
)
from rig.units import quantity


def test_units_are_converted_once_to_si():
    assert quantity("4.76 mm", "m", "d") == 0.00476
    assert quantity("0.1226 g", "kg", "m") == 0.0001226
    assert quantity("1.46 GPa", "Pa", "E") == 1.46e9
    b = Bead("ptfe", "4.76 mm", "0.1226 g")
    assert (b.diameter, b.mass) == (0.00476, 0.0001226)


def test_published_gauge_bead_mass():
    g = GaugeBead.like(Bead("ptfe", "4.76 mm", "0.1226 g"))
    assert g.mass == pytest.approx(0.116e-3, rel=1e-12)  # caps 0.093 g + plate 0.023 g
    assert MagneticBead().mass == 0.5e-3 and MagneticBead().diameter == 5e-3


def test_hertz_constant_of_identical_spheres_and_sphere_on_flat():
    E, nu, R = 193e9, 0.3, 2.38e-3
    assert hertz_constant(E, nu, R, E, nu, R) == pytest.approx(E * math.sqrt(2 * R) / (3 * (1 - nu**2)), rel=1e-14)
    # sphere on a flat of the same material: R_eff = R, E_eff = E / (2 (1 - nu^2))
    assert hertz_constant(E, nu, R, E, nu) == pytest.approx(4 / 3 * E / (2 * (1 - nu**2)) * math.sqrt(R), rel=1e-14)


def test_energy_is_the_integral_of_force_and_overlaps_invert_the_law():
    A, d, h = 4.2e7, 1.3e-5, 1e-10
    assert (hertz_energy(A, d + h) - hertz_energy(A, d - h)) / (2 * h) == pytest.approx(hertz_force(A, d), rel=1e-8)
    assert hertz_force(A, -1e-6) == 0.0
    assert hertz_force(A, static_overlaps(A, 2.38)) == pytest.approx(2.38, rel=1e-14)


@pytest.mark.parametrize("make,field", [
    (lambda: Bead("ptfe", "4.76 mm", "-0.1 g"), "bead.mass"),
    (lambda: Bead("ptfe", "0 mm"), "bead.diameter"),
    (lambda: Bead("unobtainium", "4.76 mm"), "material"),
    (lambda: Bead("ptfe", "4.76"), "bead.diameter"),
    (lambda: Bead("ptfe", "4.76 kg"), "bead.diameter"),
    (lambda: Striker(gap="-0.1 mm"), "striker.gap"),
    (lambda: Striker(velocity="-1 m/s"), "striker.velocity"),
])
def test_bad_parts_name_the_field(make, field):
    with pytest.raises(RigError, match=field.replace(".", r"\.")):
        make()


@pytest.mark.parametrize("nu", [0.5, 0.7, -1.0])
def test_poisson_ratio_outside_its_range_is_refused(nu):
    from rig import Material
    with pytest.raises(RigError, match=r"nu.*\(-1, 0\.5\)"):
        Material("x", 1e9, nu, 1000.0, "test")


def test_material_table_has_the_published_values():
    assert (material("ptfe").E, material("ptfe").nu) == (1.46e9, 0.46)
    assert (material("steel316").E, material("alumina").E, material("brass").E) == (193e9, 416e9, 115e9)
    assert Wall().material.name == "brass"
