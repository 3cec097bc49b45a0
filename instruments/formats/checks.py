"""What every scope-file reader checks alike: that a record is one analog voltage record
in time (``analog_only``: not digital, IQ, a spectrum, an RF trace, floating-point values or
a FastFrame set, told from the header before any sample is read; its horizontal unit is
seconds), and a channel name the archive can store, made from whatever the file gives (a
source like "CH1", or a file name like "Tek000-ch1 (2)")."""
from __future__ import annotations

import math
import re

import numpy as np

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


# a digital source as the manuals name it: D0-D15, CH1_D0-CH8_D7 (4/5/6 Series), DAll
_DIGITAL_SOURCE = re.compile(r"^\s*(D\d+|CH\d+_D\d+|DALL|DIGITAL)\b", re.IGNORECASE)
ANALOG = "the rig reads analog voltage records in time"


def analog_only(path, *, waveform_type: str = "", domain: str = "", source: str = "", number_format: str = "",
                frames: str = "", iq_keys: bool = False, digital_type: str = "") -> None:
    """InstrumentError in one line unless the header fields a reader found describe one
    analog voltage record in time; every reader of every format family (CSV, ISF, WFM)
    hands over what its header says, under these names, before it reads a sample, so that
    a refusal names what the record is (never a byte width or a parse error):

    - ``waveform_type``: CSV "Waveform Type" (ANALOG, DIGITAL, IQ), ISF WFMTYPE (ANALOG,
      RF_TD, RF_FD, DIGITAL); ``digital_type``: CSV "Digital Type"; ``source``: the source
      or column named (D0, CH1_D3, DAll are digital); ``iq_keys``: the IQ_centerFrequency,
      IQ_span ... rows or tekmeta keys of an IQ record;
    - ``domain``: ISF DOMAIN (TIME, FREQUENCY) (the horizontal unit is time_axis's:
      each reader names its own field);
    - ``number_format``: ISF BN_FMT (FP: floating-point values, which a math or RF record
      holds; the rig reads integer codes); ``frames``: the count of a FastFrame set."""
    kind = waveform_type.strip().strip('"').upper()
    if kind.startswith("DIGITAL") or digital_type.strip() or _DIGITAL_SOURCE.match(source or ""):
        said = (f"Waveform Type = {waveform_type.strip()}" if kind else
                f"Digital Type = {digital_type.strip()}" if digital_type.strip() else f"source {source.strip()}")
        raise InstrumentError(f"{path}: a digital waveform ({said}: logic states, not volts); {ANALOG}")
    if iq_keys or kind in ("IQ", "RF_BB_IQ"):
        said = "IQ_ keys in the header" if iq_keys else f"Waveform Type = {waveform_type.strip()}"
        raise InstrumentError(f"{path}: an IQ waveform (interleaved I and Q samples, {said}); {ANALOG}")
    if domain.strip().upper().startswith("FREQ") or kind in ("RF_FD", "SPECTRUM", "FFT"):
        said = ", ".join(f"{k} = {v.strip()}" for k, v in (("DOMAIN", domain), ("type", waveform_type)) if v.strip())
        raise InstrumentError(f"{path}: a frequency-domain record (a spectrum: FFT/MATH or RF; {said}); {ANALOG}")
    if kind.startswith("RF"):
        raise InstrumentError(f"{path}: an RF trace (type = {waveform_type.strip()}: amplitude, phase or frequency "
                              f"against time, not a voltage); {ANALOG}")
    if number_format.strip().upper().startswith("FP"):
        raise InstrumentError(f"{path}: floating-point values (BN_FMT = {number_format.strip()}: a math, reference "
                              f"or RF record); the rig reads integer codes of 1 or 2 bytes")
    count = _whole(frames)
    if count is not None and count > 1:
        raise InstrumentError(f"{path}: a FastFrame waveform set ({count} frames); the rig reads single-record "
                              f"files (save one frame)")


def _whole(text) -> int | None:
    try:
        value = float(text)
    except (TypeError, ValueError):
        return None
    return int(value) if math.isfinite(value) else None


_VOLTS = {"volts": "V", "volt": "V", "v": "V"}


def vertical_unit(text) -> str:
    """A record's vertical unit as the archive and the analysis name it: "V" for every way
    a scope writes volts ("V", "Volts", "volt"), any other unit ("A", "dB", "W") as given."""
    unit = (text or "V").strip().strip('"') or "V"
    return _VOLTS.get(unit.lower(), unit)


def channel_name(text: str) -> str:
    """A channel name the archive stores (letters, digits, '_' and '#', not starting with a
    digit), made from ``text``: every other character becomes '_', and a leading digit
    gets 'CH_' before it. "Tek000-ch1" -> "Tek000_ch1", "2024 run 3" -> "CH_2024_run_3"."""
    name = re.sub(r"[^A-Za-z0-9_#]", "_", text.strip()) or "CH"
    return f"CH_{name}" if name[0].isdigit() or name[0] == "#" else name


def is_number(text) -> bool:
    """Whether ``text`` reads as one float (nan and inf included: the callers say why each
    is refused)."""
    try:
        float(text)
    except (TypeError, ValueError):
        return False
    return True


def printed_quantum(cell) -> float:
    """The unit in the last digit a file prints of one number (its rounding is at most half
    of it): ``24999.16015625`` -> 1e-8, ``-8.000e-01`` -> 1e-4, ``2000`` -> 1; 0 where the
    cell is no number."""
    parsed = _NUMBER.match(str(cell)) if is_number(str(cell)) else None  # no printed number: '', '.', 'e5'
    if parsed is None:
        return 0.0
    _, fraction, exponent = parsed.groups()
    return 10.0 ** (int(exponent or 0) - len(fraction or ""))


_NUMBER = re.compile(r"^\s*[-+]?(\d*)(?:\.(\d*))?(?:[eE]([-+]?\d+))?\s*$")


def printed_quanta(cells) -> np.ndarray:
    """The unit in the last digit each cell of a column is printed to, from the digits of
    the whole column: a scope prints a column in one format, with S significant digits (a
    fixed form keeps its trailing zeros, ``-8.000e-01``; a shortest form drops them,
    ``0.00000067`` beside ``0.000000671``, so the cell with the most digits shows S), so a
    non-zero cell of magnitude 10^e is rounded to 10^(e - S + 1) at most; a column printed
    with fixed decimals (``-0.000000329``) rounds no cell finer than its most decimals
    allow. A zero is exact in the exponent and shortest forms (a non-zero time prints its
    own digits). A TBS1000C's ``6.109e-05`` -> 1e-8, a TDS2001C's ``0.00000067`` (three
    digits, the column's most) -> 1e-9."""
    parts = [_NUMBER.match(str(c)) for c in cells]
    digits = []  # (significant digits, exponent of the leading digit, decimals of a plain cell or -1)
    for m in parts:
        if m is None:
            digits.append((0, 0, -1))
            continue
        whole, fraction, exponent = m.group(1), m.group(2) or "", m.group(3)
        mantissa = (whole + fraction).lstrip("0")
        if not mantissa:
            digits.append((0, 0, -1))  # a zero
            continue
        lead = len(whole.lstrip("0")) - 1 if whole.lstrip("0") else -(len(fraction) - len(fraction.lstrip("0"))) - 1
        digits.append((len(mantissa.rstrip("0")) if exponent is None and not fraction else len(mantissa),
                       int(exponent or 0) + lead, len(fraction) if exponent is None else -1))
    significant = max((d[0] for d in digits), default=0)
    decimals = max((d[2] for d in digits if d[0]), default=-1)
    quanta = np.array([10.0 ** (e - significant + 1) if s else 0.0 for s, e, _ in digits])
    return np.maximum(quanta, 10.0 ** -decimals) if decimals >= 0 else quanta


def screen(scale, offset, position) -> dict:
    """The screen a header gives (V/div, offset V, position div), as the preamble's extra
    keeps it for instruments.rails and the exports: {"volts_per_div", "vertical_offset_V",
    "position_div"}; {} where the scale is missing or not a finite number > 0."""
    def number(text, default):
        try:
            value = float(text if text not in (None, "") else default)
        except (TypeError, ValueError):
            return None
        return value if math.isfinite(value) else None

    values = number(scale, "nan"), number(offset, 0), number(position, 0)
    if values[0] is None or values[0] <= 0 or None in values:
        return {}
    return {"volts_per_div": values[0], "vertical_offset_V": values[1], "position_div": values[2]}


def bandwidth(text) -> dict:
    """{"bandwidth_Hz": B} from a header's filter frequency (ISF FILTERF, CSV "Filter
    Frequency"), as the preamble's extra keeps a channel's bandwidth limit; {} where the
    header gives none or no positive number."""
    try:
        value = float(text)
    except (TypeError, ValueError):
        return {}
    return {"bandwidth_Hz": value} if math.isfinite(value) and value > 0 else {}
