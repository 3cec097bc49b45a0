"""Numeric program data (IEEE 488.2 7.7.2, SCPI 1999 7.2): decimal numbers (NR1, NR2, NR3),
non-decimal ``#H``/``#Q``/``#B`` numbers, and a suffix: an optional SCPI multiplier
(EX PE T G MA K M U N P F A; ``M`` is milli, ``MA`` mega, and ``MHZ``/``MOHM`` mega) before
the unit the command expects, case-insensitive (``50mV``, ``10 us``, ``2.5MHz``)."""
from __future__ import annotations

import math
import re

from .status import ScpiError

DECIMAL = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?")
NON_DECIMAL = {"H": (16, "0123456789ABCDEF"), "Q": (8, "01234567"), "B": (2, "01")}
MULTIPLIERS = {"EX": 1e18, "PE": 1e15, "T": 1e12, "G": 1e9, "MA": 1e6, "K": 1e3, "M": 1e-3,
               "U": 1e-6, "N": 1e-9, "P": 1e-12, "F": 1e-15, "A": 1e-18}
MEGA_UNITS = ("HZ", "OHM")  # "MHZ" is megahertz, "MOHM" megaohm (SCPI 1999 7.2.3)


def split_number(text: str) -> tuple[float, str]:
    """(value, suffix as sent) of a numeric argument; ScpiError -104 when it is no number."""
    t = text.strip()
    if t[:1] == "#" and t[1:2].upper() in NON_DECIMAL:
        base, digits = NON_DECIMAL[t[1:2].upper()]
        if len(t) > 2 and all(c in digits for c in t[2:].upper()):
            return float(int(t[2:], base)), ""
        raise ScpiError(-104, f"{text!r} is no #{t[1:2].upper()} number")
    m = DECIMAL.match(t)
    if not m:
        raise ScpiError(-104, f"{text!r} is not a number")
    value = float(m.group())
    if not math.isfinite(value):
        raise ScpiError(-120, f"{text!r} is not a finite number")
    return value, t[m.end():].strip()


def scale_of(suffix: str, unit: str) -> float:
    """The factor a suffix applies for a command whose unit is ``unit`` ("V", "S", "HZ";
    "" for none); ScpiError -131 for a suffix that is not [multiplier]unit."""
    s, u = suffix.upper(), unit.upper()
    if not s:
        return 1.0
    if u and s == u:
        return 1.0
    if u and s.endswith(u):
        head = s[: -len(u)]
        if head == "M" and u in MEGA_UNITS:
            return 1e6
        if head in MULTIPLIERS:
            return MULTIPLIERS[head]
    allowed = f"[multiplier]{unit}" if unit else "no unit"
    raise ScpiError(-131, f"{suffix!r}: allowed {allowed}")


def number(text: str, unit: str = "") -> float:
    """A numeric argument in SI units."""
    value, suffix = split_number(text)
    scaled = value * scale_of(suffix, unit)
    if not math.isfinite(scaled):
        raise ScpiError(-120, f"{text!r} is not a finite number")
    return scaled
