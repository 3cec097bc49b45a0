"""Quantities with units, converted to SI floats once, at the boundary.

``quantity("4.76 mm", "m", field="bead.diameter")`` returns ``0.00476``. pint is the
authority on units; the plain forms of scene files ("NUMBER UNIT" or "NUMBER UNIT/UNIT",
SI units with SI prefixes, integer powers) are converted by a small table first, since
loading pint and its registry costs about a quarter of a second; anything else goes to
pint. Both round to 15 significant digits, which drops the conversion's last-bit noise, so
they give the same floats (tests/model/test_units.py compares them).
"""
from __future__ import annotations

import functools
import math
import numbers
import re

from rig.errors import RigError, invalid


@functools.lru_cache(maxsize=1)
def _registry():
    import pint

    return pint.UnitRegistry(cache_folder=":auto:")


MAX_SEED = 2**63 - 1  # seeds are stored as signed 64-bit integers

Quantity = float | str
"""What a part takes for a physical value: a number in SI units, or a string with its unit
("4.76 mm", "0.47 g"); the part keeps the SI float (``quantity``)."""


def is_real(x) -> bool:
    """A real number, numpy's scalars included, and not a bool (True is not 1 s)."""
    return isinstance(x, numbers.Real) and not isinstance(x, bool)


def is_whole(x) -> bool:
    """A whole number, numpy's integers included, and not a bool."""
    return isinstance(x, numbers.Integral) and not isinstance(x, bool)


_DECIMAL_COMMA = re.compile(r"\d,\d")
_SEPARATOR = r"(?:[_'’\u00a0\u202f]|\s+)"
_GROUPED = re.compile(rf"\d{_SEPARATOR}\d")  # 1_000, 1'000, 1 000
_GROUPED_RUN = re.compile(rf"[0-9]+(?:{_SEPARATOR}[0-9]+)+")  # the whole run of grouped digits
_NUMBER_TEXT = r"[-+]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][-+]?[0-9]+)?"
_UNIT_FACTOR = r"[^\W\d_]+(?:\s*(?:\^|\*\*)\s*[-+]?[0-9]+(?:\.[0-9]+)?)?"
_UNIT_TEXT = rf"{_UNIT_FACTOR}(?:\s*[*/]\s*{_UNIT_FACTOR}|\s+{_UNIT_FACTOR})*"
_PLAIN = re.compile(rf"\s*({_NUMBER_TEXT})\s*$")
_QUANTITY = re.compile(rf"\s*({_NUMBER_TEXT})\s*({_UNIT_TEXT})\s*$")


def check_digits(text: str, field: str):
    """Refuse a decimal comma ("1,2") or a thousands separator ("1 000", "1_000", "1'000")
    in the text of a number or a quantity, naming ``field``: Python and pint would read
    "1,2" as 12 and "1 200" as 1 x 200. The example given is the text's own number
    written without the separator."""
    if _DECIMAL_COMMA.search(text):
        raise invalid(field, text, "use a decimal point and no thousands separator (1.2, 1200)")
    if _GROUPED.search(text):
        run = _GROUPED_RUN.search(text)
        example = re.sub(_SEPARATOR, "", run.group(0)) if run else "1200"
        raise invalid(field, text, f"one number, no thousands separator ({example})")


def is_number(text) -> bool:
    """``text`` is one plain number as the rig reads it: an optional sign, ASCII digits with
    at most one decimal point, an optional exponent that is a whole number ("1.5e-3");
    no unit, no expression ("2*0.5", "1.2.3"), no other script's digits."""
    return isinstance(text, str) and _PLAIN.match(text) is not None


def is_non_finite(text) -> bool:
    """``text`` names a number that is not finite ("nan", "inf", "-Infinity"): read right by
    Python, refused as "a finite number" rather than as a mistyped one."""
    return isinstance(text, str) and text.strip().lstrip("+-").lower() in ("nan", "inf", "infinity")


def split_quantity(text: str, field: str, unit: str) -> tuple:
    """(number text, unit text) of a quantity's text: ONE number (``is_number``) followed
    by a unit expression of unit names joined by '*', '/' or spaces, each with an optional
    exponent after '^' or '**' ("m/s", "N/m^1.5", "kg m^-3", "µs"); anything else
    ("2.3.8 N", "0.5(2) m", "1e-1.5 m/s", "2*0.5 m") is refused naming ``field``."""
    check_digits(text, field)
    if is_non_finite(text.split()[0] if text.split() else text):
        raise invalid(field, text, "must be a finite number")
    m = _QUANTITY.match(text)
    if not m:
        raise invalid(field, text, f"not a quantity: one number and a unit, e.g. '1.5 {unit}' (digits 0-9, one "
                                   "decimal point, a whole-number exponent; no arithmetic)")
    if m.end(1) == m.start(2) and m.group(2)[0] in "jJ":  # Python and pint read "5J" as 5j
        raise invalid(field, text, f"not a quantity: '{m.group(0).strip()}' reads as a complex number; "
                                   f"a space between the number and the unit: '{m.group(1)} {m.group(2)}'")
    return m.group(1), m.group(2)


def number(text, field: str, allowed: str = "a finite number") -> float:
    """The plain number ``text`` (no unit) as a float: a decimal point, no thousands
    separator, finite; else RigError ``field = text: allowed``."""
    if is_real(text):
        value = float(text)
    elif isinstance(text, str):
        check_digits(text, field)
        if not (is_number(text) or is_non_finite(text)):
            raise invalid(field, text, allowed)
        value = float(text)
    else:
        raise invalid(field, text, allowed)
    if not math.isfinite(value):
        raise invalid(field, text, allowed)
    return value


def whole(text, field: str, allowed: str = "a whole number") -> int:
    """The whole number ``text`` ("30", "30.0" or "3e1" is 30; "2.5" is refused)."""
    if is_whole(text):
        return int(text)
    value = number(text, field, allowed)
    if value != int(value):
        raise invalid(field, text, allowed)
    return int(value)


def typed_quantity(text: str, unit: str | None, field: str) -> float:
    """A value as typed on the command line: a plain number is taken in ``unit`` (SI), text
    with a unit is converted to it; ``unit`` None: a plain number only."""
    check_digits(text, field)
    if unit is not None and not (is_number(text) or is_non_finite(text)):
        return quantity(text, unit, field)
    return number(text, field, "a finite number" + (f" (plain number: {unit})" if unit else ""))


def quantity(value: Quantity, unit: str, field: str, *, bare_ok: bool = False) -> float:
    """Return ``value`` expressed in ``unit`` (an SI unit such as "m", "kg", "Pa").

    ``value`` is a string with a unit ("0.47 g", "1.46 GPa"), or a plain number when
    ``bare_ok`` is true, in which case it is taken to be in ``unit`` already (a string
    always needs its unit: "4.76" is refused, 4.76 is not). Raises
    RigError naming ``field`` when the text does not parse, has no unit where one is
    required, or has the wrong dimension.
    """
    if isinstance(value, bool):
        raise invalid(field, value, f"expected a quantity in {unit}")
    if isinstance(value, numbers.Real):
        if not bare_ok:
            raise invalid(field, value, f"a unit is required, e.g. '{value} {unit}'")
        out = float(value)
    elif isinstance(value, str):
        out = _parse(value, unit, field)
    else:
        raise invalid(field, value, f"expected a quantity in {unit}, e.g. '1 {unit}'")
    if not math.isfinite(out):
        raise invalid(field, value, "must be a finite number")
    return out


# SI units by symbol: (factor to SI, dimension exponents of kg, m, s, A)
_UNITS = {"m": (1.0, (0, 1, 0, 0)), "g": (1e-3, (1, 0, 0, 0)), "s": (1.0, (0, 0, 1, 0)),
          "N": (1.0, (1, 1, -2, 0)), "Pa": (1.0, (1, -1, -2, 0)), "V": (1.0, (1, 2, -3, -1)),
          "Hz": (1.0, (0, 0, -1, 0)), "A": (1.0, (0, 0, 0, 1)), "J": (1.0, (1, 2, -2, 0))}
_PREFIXES = {"": 1.0, "G": 1e9, "M": 1e6, "k": 1e3, "c": 1e-2, "m": 1e-3, "u": 1e-6, "µ": 1e-6,
             "μ": 1e-6, "n": 1e-9, "p": 1e-12}
_FACTOR = re.compile(r"([A-Za-zµμ]+)(?:(?:\^|\*\*)(-?\d+))?$")


def _si(unit: str):
    """(factor to SI, dimension) of a unit written as factors joined by '*' and at most one
    '/' (e.g. "mm", "m/s^2", "V/N"); None where the table does not know it."""
    num, _, den = unit.partition("/")
    factor, dims = 1.0, [0, 0, 0, 0]
    for part, sign in ((num, 1), (den, -1)):
        if sign < 0 and not den:
            break
        for token in part.split("*") if "**" not in part else [part]:
            m = _FACTOR.match(token.strip())
            if not m:
                return None
            symbol, power = m.group(1), sign * int(m.group(2) or 1)
            known = [(p, symbol[len(p):]) for p in _PREFIXES if symbol.startswith(p) and symbol[len(p):] in _UNITS]
            if not known:
                return None
            prefix, base = min(known, key=lambda k: len(k[0]))  # "m" is metre, not milli-nothing
            f, d = _UNITS[base]
            factor *= (_PREFIXES[prefix] * f) ** power
            dims = [a + power * b for a, b in zip(dims, d)]
    return factor, tuple(dims)


def _fast(value: str, unit_text: str, unit: str):
    """The SI value of the number ``value`` in ``unit_text`` by the table, or None where
    pint must decide."""
    have, want = _si(unit_text), _si(unit)
    if have is None or want is None or have[1] != want[1]:
        return None
    return float(f"{float(value) * have[0] / want[0]:.15g}")


def _parse(text: str, unit: str, field: str) -> float:
    if is_number(text):
        raise invalid(field, text, f"a unit is required, e.g. '{text.strip()} {unit}'")
    value, unit_text = split_quantity(text, field, unit)
    fast = _fast(value, unit_text, unit)
    if fast is not None:
        return fast
    import pint

    ureg = _registry()
    try:
        q = ureg.Quantity(f"{value} {unit_text}")
    except (pint.errors.PintError, ValueError, TypeError, AttributeError, SyntaxError) as exc:
        raise invalid(field, text, f"not a quantity in {unit} ({exc})") from None
    if q.unitless:
        raise invalid(field, text, f"a unit is required, e.g. '{text.strip()} {unit}'")
    try:
        si = float(q.to(unit).magnitude)
    except pint.errors.DimensionalityError:
        raise invalid(field, text, f"expected a quantity convertible to {unit}") from None
    # 15 significant digits drop the conversion's last-bit noise ("4.76 mm" -> 0.00476)
    return float(f"{si:.15g}")


__all__ = ["RigError", "is_non_finite", "is_number", "number", "quantity", "split_quantity", "typed_quantity",
           "whole"]
