"""Quantities: the table of plain SI forms gives pint's floats, and scenes load without pint."""
import re
import subprocess
import sys

import pint
import pytest

from rig.errors import RigError
from rig.units import is_number, number, quantity

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


@pytest.mark.parametrize("text,unit,si", [("0.89 m/s", "m/s", 0.89), ("2 N/m^1.5", "N/m^1.5", 2.0),
                                          ("1200 kg m^-3", "kg/m^3", 1200.0), ("25 us", "s", 25e-6),
                                          ("25 µs", "s", 25e-6), ("1.46 GPa", "Pa", 1.46e9), ("-.5e+3 mm", "m", -0.5),
                                          ("3 kg*m/s**2", "N", 3.0), ("1. inch", "m", 0.0254)])
def test_one_number_and_a_unit_expression_is_a_quantity(text, unit, si):
    assert quantity(text, unit, "x") == pytest.approx(si, rel=1e-12)


@pytest.mark.parametrize("text", ["2.3.8 N", "1.200.5 N", "1.000.000 N", "2*0.5 N", "1/2 N", "0.5(2) N", "2**-1 N",
                                  "1e-1.5 N", "\u0661 N", "\uff11 N", "1 N 2", "1 N*3", "(1) N", "1 (N)", "0x10 N"])
def test_anything_but_one_number_and_a_unit_is_refused(text):
    """These had been read as a product (2.3 x 0.8 N), an expression, or another script's 1."""
    with pytest.raises(RigError, match=r"x = .*(one number and a unit|not a quantity)"):
        quantity(text, "N", "x")


@pytest.mark.parametrize("text,ok", [("1", True), ("-1.5e-3", True), (".5", True), ("1.", True), ("1.2.3", False),
                                     ("2*3", False), ("1e1.5", False), ("\u0661", False), ("1_0", False),
                                     ("nan", False), ("", False)])
def test_a_plain_number_is_ascii_digits_one_point_and_a_whole_exponent(text, ok):
    assert is_number(text) is ok
    if ok:
        assert number(text, "x") == float(text)
    else:
        with pytest.raises(RigError):
            number(text, "x")


def test_a_thousands_separator_is_refused_with_the_number_it_stands_for():
    for text, example in (("1_000 m/s", "(1000)"), ("1 200 m/s", "(1200)"), ("12'500", "(12500)")):
        with pytest.raises(RigError, match=re.escape(example)):
            quantity(text, "m/s", "x")
