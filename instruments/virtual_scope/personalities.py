"""The Tektronix models the emulated scope can claim: what they answer and what they take.

- ``tds2000``: a TDS2024C (TDS200/TDS1000/TDS2000 Series Programmer Manual, 071-1075):
  2,500-point records only, 8-bit data (``DATa:WIDth 2`` pads the low byte), the 16-field
  ``WFMPre?`` (BYT_NR, BIT_NR, ENCDG, BN_FMT, BYT_OR, NR_PT, WFID, PT_FMT, XINCR, PT_OFF,
  XZERO, XUNIT, YMULT, YZERO, YOFF, YUNIT), ``YUNit?`` "Volts", time bases in a 1-2.5-5
  sequence, numbers such as ``2.0E-6``.
- time bases of the mdo3000 in a 1-2-4 sequence (its WFID reads "400.0us/div"), of the mso4
  in 1-2-5.
- ``mdo3000`` (MDO3000 Series Programmer Manual, 077-0968) and ``mso4`` (4 Series MSO
  Programmer Manual, 077-1497): the 22-field ``WFMOutpre?`` (the 4 Series' 23 with ASC_FMT
  after BYT_OR) (... PT_ORDER, ..., DOMAIN,
  WFMTYPE, CENTERFREQUENCY, SPAN, REFLEVEL), record lengths from the model's list, 16-bit
  data with ``DATa:WIDth 2``, numbers in engineering notation such as ``400.0000E-9``,
  ``1.0000``, ``0.0E+0``; the 4 Series' ``CURVEStream?`` (stream.py).
Every model: V/div in a 1-2-5 sequence, 25 codes per division of the 8-bit converter."""
from __future__ import annotations

import math
import re
from dataclasses import dataclass
from decimal import Decimal

from ..devices.oscilloscope import per_division
from ..errors import InstrumentError

WFMPRE_16 = ("BYT_Nr", "BIT_Nr", "ENCdg", "BN_Fmt", "BYT_Or", "NR_Pt", "WFId", "PT_Fmt", "XINcr", "PT_Off",
             "XZEro", "XUNit", "YMUlt", "YZEro", "YOFf", "YUNit")
WFMOUTPRE_22 = ("BYT_Nr", "BIT_Nr", "ENCdg", "BN_Fmt", "BYT_Or", "WFId", "NR_Pt", "PT_Fmt", "PT_ORder", "XUNit",
                "XINcr", "XZEro", "PT_Off", "YUNit", "YMUlt", "YOFf", "YZEro", "DOMain", "WFMTYpe",
                "CENTERFREQuency", "SPAN", "REFLevel")
WFMOUTPRE_4SERIES = WFMOUTPRE_22[:5] + ("ASC_Fmt",) + WFMOUTPRE_22[5:]
"""The 4 Series' WFMOutpre? (23 fields): ASC_FMT, the form of ASCII data, after BYT_OR, as the
4 Series' command tree lists it and its clients read it (pymeasure's MSO44: WFID at index 6)."""


@dataclass(frozen=True)
class Personality:
    """A model's identity and reply forms.

    idn: the ``*IDN?`` reply; record_lengths (points, ascending); time_steps: the mantissas
    of s/div in a decade; preamble: "WFMPre" (16 fields) or "WFMOutpre" (22); preamble_fields
    in reply order; y_unit: YUNit's text; engineering: numbers with an exponent that is a
    multiple of 3 and at least 4 decimals (MDO, MSO) or plain NR3 (TDS); wfid_digits: the
    significant digits of V/div and s/div in WFID; encodings: DATa:ENCdg's words in its manual
(the MDO3000's add FAStest, FPBinary and SFPbinary, the 4 Series' FPBinary and SFPbinary)."""

    name: str
    idn: str
    record_lengths: tuple
    time_steps: tuple
    preamble: str
    preamble_fields: tuple
    y_unit: str
    engineering: bool
    wfid_digits: int
    volt_steps: tuple = (1.0, 2.0, 5.0)
    encodings: tuple = ("ASCIi", "RIBinary", "RPBinary", "SRIbinary", "SRPbinary")
    models: str = ""
    """The models whose programmer manual the personality follows (a regular expression of
    ``*IDN?``'s model field): the only ones ``idn`` may claim; model_names says them."""
    model_names: str = ""
    streams: bool = False
    """Whether the model's manual has CURVEStream? (the 4 Series'; not the TDS2000's nor
    the MDO3000's)."""
    horizontal_modes: bool = False
    """Whether the model's manual has HORizontal:MODe {AUTO|MANual} (the 4 Series'): see
    horizontal.py."""
    source_list: bool = False
    """Whether DATa:SOUrce takes a list, ``<wfm>[<,><wfm>]`` (the 4 Series' manual); the
    TDS2000's and MDO3000's take one source (``{CH<x>|MATH|...}``)."""
    max_sample_rate: float | None = None
    """The highest real-time sample rate (S/s) its horizontal modes keep to (the 4 Series:
    6.25 GS/s on every channel, 4 Series MSO datasheet); None: not bounded here."""
    scale_range: tuple | None = None
    """(fastest, slowest) s/div its time base takes; a scale beyond is taken at the nearer end,
    as the manuals force a numeric argument "to a valid setting" (the TDS2000C's "5 ns/div to
    50 s/div, in a 1, 2.5, 5 sequence", its user manual's horizontal specifications); None:
    not bounded here."""

    @property
    def combined_offset(self) -> bool:
        """Whether WFMOutpre:YZEro holds the vertical position and offset and YOFf is always 0
        (the MDO3000's and 4 Series' manuals); the TDS2000's YOFf is the position in codes."""
        return self.preamble == "WFMOutpre"

    @property
    def floats(self) -> bool:
        """Whether the model sends 4-byte floats (DATa:ENCdg FPBinary, BN_Fmt FP)."""
        return "FPBinary" in self.encodings

    def number(self, x: float) -> str:
        """x in the model's notation, with every digit needed to read it back exactly."""
        d = Decimal(repr(float(x)))
        if d == 0:
            return "0.0E+0" if self.engineering else "0.0E0"
        exp = d.adjusted()
        if self.engineering:
            exp = 3 * math.floor(exp / 3)
        mant = d.scaleb(-exp).normalize()
        decimals = max(4 if self.engineering else 1, -int(mant.as_tuple().exponent))
        text = f"{mant:.{decimals}f}"
        if self.engineering:
            return text if exp == 0 else f"{text}E{exp:+d}"
        return f"{text}E{exp}"

    def per_div(self, x: float, unit: str) -> str:
        """A V/div or s/div figure as WFID prints it: ``50.00mV``, ``10.00us`` on the MDO and
        MSO; in NR3 and a space on the TDS, ``5.0E-2 V``, ``2.5E-4 s`` (the TDS1000/2000
        answer "Ch1, DC coupling, 5.0E-1 V/div, 5.0E-2 s/div, 2500 points, Sample mode")."""
        return per_division(x, unit, self.wfid_digits) if self.engineering else f"{self.number(x)} {unit}"


PERSONALITIES = {
    "tds2000": Personality("tds2000", "TEKTRONIX,TDS 2024C,C010001,CF:91.1CT FV:v24.26", (2500,),
                           (1.0, 2.5, 5.0), "WFMPre", WFMPRE_16, "Volts", False, 3,
                           models=r"TDS ?(2[0-9]{2}|1[0-9]{3}[A-Z]?|2[0-9]{3}[A-Z]?)(-EDU)?|TPS ?20[0-9]{2}[A-Z]?",
                           model_names="TDS 210 to TDS 224, TDS 1001 to TDS 2024 (B, C), TPS 2012 to TPS 2024",
                           scale_range=(5e-9, 50.0)),
    "mdo3000": Personality("mdo3000", "TEKTRONIX,MDO3024,C010001,CF:91.1CT FV:v1.30", (1000, 10000, 100000, 1000000,
                                                                                      5000000, 10000000),
                           (1.0, 2.0, 4.0), "WFMOutpre", WFMOUTPRE_22, "V", True, 4,
                           encodings=("ASCIi", "FAStest", "RIBinary", "RPBinary", "SRIbinary", "SRPbinary",
                                      "FPBinary", "SFPbinary"), models=r"MDO3[0-9]{3}",
                           model_names="MDO3012 to MDO3104"),
    "mso4": Personality("mso4", "TEKTRONIX,MSO44,C010001,CF:91.1CT FV:2.0.3.950",
                        (1000, 2000, 5000, 10000, 20000, 50000, 100000, 200000, 500000, 1000000, 2000000, 5000000,
                         10000000, 20000000, 31250000),
                        (1.0, 2.0, 5.0), "WFMOutpre", WFMOUTPRE_4SERIES, "V", True, 4,
                        encodings=("ASCIi", "RIBinary", "RPBinary", "FPBinary", "SRIbinary", "SRPbinary", "SFPbinary"),
                        models=r"MSO4[4-8]B?", model_names="MSO44, MSO46, MSO48 (B too)", streams=True,
                        source_list=True, horizontal_modes=True, max_sample_rate=6.25e9),
}


def personality(name: str, idn: str | None = None) -> Personality:
    """A personality by name, its ``*IDN?`` replaced by ``idn`` where given."""
    if name not in PERSONALITIES:
        raise InstrumentError(f"personality = {name!r}: allowed {', '.join(PERSONALITIES)}")
    p = PERSONALITIES[name]
    if idn is not None:
        fields = idn.split(",")
        if len(fields) != 4 or not all(f.strip() for f in fields) or not idn.isprintable():
            raise InstrumentError(f"idn = {idn!r}: allowed four comma-separated fields, "
                                  f"MAKER,MODEL,SERIAL,FIRMWARE (e.g. TEKTRONIX,MSO44,C000001,FV:1.0)")
        maker, model = fields[0].strip().upper(), fields[1].strip().upper()
        if maker != "TEKTRONIX" or not re.fullmatch(p.models, model):
            raise InstrumentError(f"idn = {idn!r}: the {name} personality answers as the models of its manual, "
                                  f"TEKTRONIX {p.model_names}; another model's commands differ")
        p = Personality(**{**p.__dict__, "idn": idn})
    return p


def snap_to_steps(x: float, mantissas) -> float:
    """The value of a 1-2-5 (or 1-2.5-5) sequence nearest x (> 0) on a log scale; x beyond
    1e-15 .. 1e15 is taken at that bound (no scope setting is near it; the bounds refuse it)."""
    decade = math.floor(math.log10(min(max(x, 1e-15), 1e15)))
    candidates = [m * 10.0 ** e for e in (decade - 1, decade, decade + 1) for m in mantissas]
    best = min(candidates, key=lambda c: abs(math.log(c / x)))
    return float(f"{best:.12g}")


def snap_record_length(n: float, lengths) -> int | None:
    """The model's record length nearest n on a log scale, or None outside its range."""
    if not lengths[0] * 0.999 <= n <= lengths[-1] * 1.001:
        return None
    return min(lengths, key=lambda c: abs(math.log(c / n)))
