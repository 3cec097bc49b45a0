"""Quantities with units, converted to SI floats once, at the boundary.

``quantity("4.76 mm", "m", field="bead.diameter")`` returns ``0.00476``. Parsing uses
pint; the registry is built lazily (first use) so that importing the rig stays cheap.
"""
from __future__ import annotations

import functools
import math
import numbers

from rig.errors import RigError, invalid


@functools.lru_cache(maxsize=1)
def _registry():
    import pint

    return pint.UnitRegistry(cache_folder=":auto:")


def quantity(value, unit: str, field: str, *, bare_ok: bool = False) -> float:
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


def _parse(text: str, unit: str, field: str) -> float:
    import pint

    ureg = _registry()
    try:
        q = ureg.Quantity(text.strip())
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


__all__ = ["quantity", "RigError"]
