"""What every scope-file reader checks alike: that a record runs in time (its horizontal
unit is seconds), and a channel name the archive can store, made from whatever the file
gives (a source like "CH1", or a file name like "Tek000-ch1 (2)")."""
from __future__ import annotations

import math
import re

from ..errors import InstrumentError

SECONDS = ("s", "sec", "second", "seconds")


def time_axis(path, field: str, unit: str) -> str:
    """'s' where the record's horizontal unit ``unit`` (named ``field`` in the file) is
    seconds; otherwise InstrumentError in one line: a spectrum (hertz) is named as the
    frequency-domain record it is, never read as a time record holding hertz."""
    u = (unit or "s").strip().strip('"')
    if u.lower() in SECONDS:
        return "s"
    what = ("a frequency-domain record (an FFT/MATH spectrum)" if u.lower() in ("hz", "hertz")
            else "not a time record")
    raise InstrumentError(f"{path}: {what}: {field} = {u!r}; the rig reads time records "
                          f"(horizontal unit s)")


def channel_name(text: str) -> str:
    """A channel name the archive stores (letters, digits, '_' and '#', not starting with a
    digit), made from ``text``: every other character becomes '_', and a leading digit
    gets 'CH_' before it. "Tek000-ch1" -> "Tek000_ch1", "2024 run 3" -> "CH_2024_run_3"."""
    name = re.sub(r"[^A-Za-z0-9_#]", "_", text.strip()) or "CH"
    return f"CH_{name}" if name[0].isdigit() or name[0] == "#" else name


def printed_quantum(cell) -> float:
    """The unit in the last digit a file prints of a number (its rounding is at most half
    of it): ``6.109e-05`` -> 1e-8, ``-8.000e-01`` -> 1e-4, ``0.0008`` -> 1e-4,
    ``1.00E-09`` -> 1e-11, ``24999.16015625`` -> 1e-8, ``2000`` -> 1. What a file prints
    is all it promises: a shortest form (``0.0008``) is taken to its last digit too."""
    mantissa, _, exponent = str(cell).strip().lower().partition("e")
    try:
        power = int(exponent) if exponent else 0
    except ValueError:
        return 0.0  # no printed number: no rounding to allow for (the caller reads the value)
    return 10.0 ** (power - len(mantissa.partition(".")[2]))


def bandwidth(text) -> dict:
    """{"bandwidth_Hz": B} from a header's filter frequency (ISF FILTERF, CSV "Filter
    Frequency"), as the preamble's extra keeps a channel's bandwidth limit; {} where the
    header gives none or no positive number."""
    try:
        value = float(text)
    except (TypeError, ValueError):
        return {}
    return {"bandwidth_Hz": value} if math.isfinite(value) and value > 0 else {}
