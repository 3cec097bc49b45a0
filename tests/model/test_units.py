"""Quantities: the table of plain SI forms gives pint's floats, and scenes load without pint."""
import subprocess
import sys

import pint
import pytest

from rig.errors import RigError
from rig.units import quantity

CASES = [("4.76 mm", "m"), ("0.47 g", "kg"), ("0.89 m/s", "m/s"), ("2.38 N", "N"), ("1.46 GPa", "Pa"),
         ("3 ms", "s"), ("0.2 us", "s"), ("50 mV", "V"), ("20 MHz", "Hz"), ("0.05 V/N", "V/N"),
         ("9.80665 m/s^2", "m/s^2"), ("10 m/s**2", "m/s^2"), ("0.1226 g", "kg"), ("0.0008 g", "kg"),
         ("12.7 mm", "m"), ("1 mm/us", "m/s"), ("5 kN", "N"), ("0.3 mV/N", "V/N"), ("7 ns", "s"),
         ("-1.5e-3 mm", "m"), (".5 km", "m"), ("3 mg", "kg"), ("200 GPa", "Pa"), ("4.76mm", "m"),
         ("1.2 cm", "m"), ("250 kHz", "Hz"), ("0.5 kg", "kg"), ("1 J", "J"), ("2 mA", "A")]


@pytest.mark.parametrize("text,unit", CASES)
def test_plain_forms_give_pints_floats(text, unit):
    ureg = pint.UnitRegistry()
    expected = float(f"{float(ureg.Quantity(text).to(unit).magnitude):.15g}")
    assert quantity(text, unit, "x") == expected


@pytest.mark.parametrize("text,unit", [("1 inch", "m"), ("3 min", "s"), ("1 lbf", "N"), ("2 kgf", "N")])
def test_other_units_go_to_pint(text, unit):
    ureg = pint.UnitRegistry()
    assert quantity(text, unit, "x") == float(f"{float(ureg.Quantity(text).to(unit).magnitude):.15g}")


@pytest.mark.parametrize("text,message", [("4.76", "a unit is required"), ("1 kg", "convertible to m"),
                                          ("fast", "not a quantity")])
def test_mistakes_name_the_field(text, message):
    with pytest.raises(RigError, match=f"bead.diameter = '{text}': .*{message}"):
        quantity(text, "m", "bead.diameter")


def test_published_scenes_load_without_pint():
    code = ("import sys; from rig.experiment.scene import PUBLISHED_SCENES, load\n"
            "[load(p) for p in sorted(PUBLISHED_SCENES.rglob('*.toml'))]\n"
            "print('pint' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


@pytest.mark.parametrize("text", ["1e3J", "5e0J"])
def test_what_pint_reads_as_a_complex_number_is_refused_as_pint_refuses_it(text):
    with pytest.raises(RigError, match="not a quantity"):
        quantity(text, "J", "x")
