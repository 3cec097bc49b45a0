"""A record's waveform as a Tektronix scope sends it: ``CURVe?`` and its preamble.

``DATa:ENCdg`` (programmer manuals, "DATa:ENCdg"): ASCIi (comma-separated codes), RIBinary
(signed, MSB first), RPBinary (unsigned, MSB first), SRIbinary and SRPbinary (the same, LSB
first); on the models whose manuals list them, FPBinary and SFPbinary (4-byte IEEE floats,
MSB or LSB first: BYT_NR 4, BN_FMT FP; the 8-bit codes as floats, YMULT and YOFF those of
1-byte codes) and FAStest (the MDO3000's "fastest": RIBinary). ``DATa:WIDth 2`` sends the
8-bit converter's code in the high byte (code x 256), as the scopes do, so YMULT is
V/div / 25 / 256. An unsigned encoding adds 2^(8 width - 1)
to every code and to YOFF (on the MDO3000 and 4 Series, whose YOFF is always 0, YZERO takes
it with the position: ``scaled``). The preamble (``WFMPre?``/``WFMOutpre?``) always describes the
bytes ``CURVe?`` sends with the current DATa settings: NR_PT the points from STARt to STOP
(clipped to the record), XZERO the time of the first point sent (s from the trigger),
PT_OFF 0, so volts = YZERO + YMULT (code - YOFF) and t = XZERO + XINCR n."""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..records import Preamble
from ..scpi.blocks import definite_block
from ..scpi.engine import Fields, Word
from .personalities import Personality

ENCODINGS = ("ASCIi", "RIBinary", "RPBinary", "SRIbinary", "SRPbinary")
FLOATS = ("FPBinary", "SFPbinary")
FASTEST = "FAStest"
BINARY = {(True, True): "RIBinary", (False, True): "RPBinary", (True, False): "SRIbinary", (False, False): "SRPbinary"}
"""(signed, MSB first) -> the binary encoding of integer codes."""


@dataclass(frozen=True)
class DataSelection:
    """The DATa settings: source channel, first and last point (1-based, inclusive),
    encoding (one of ENCODINGS), bytes per point (1 or 2); binary: the binary encoding
    the preamble names (BN_FMT, BYT_OR) and ``ENCdg BINary`` returns to, kept under ASCIi."""

    source: str = "CH1"
    sources: tuple = ()  # DATa:SOUrce's list where a client named more than one (the first is ``source``)
    start: int = 1
    stop: int = 10_000
    encoding: str = "RIBinary"
    width: int = 1
    binary: str = "RIBinary"

    def encoded(self, encoding: str) -> DataSelection:
        """These settings with ``DATa:ENCdg encoding`` (FAStest: RIBinary)."""
        encoding = "RIBinary" if encoding == FASTEST else encoding
        return replace(self, encoding=encoding, binary=self.binary if encoding == "ASCIi" else encoding)

    def formatted(self, *, signed: bool | None = None, msb_first: bool | None = None,
                  floating: bool | None = None) -> DataSelection:
        """These settings with the preamble's BN_Fmt (signed: RI/RP, or floating: FP) or BYT_Or
        (msb_first) set, as ``WFMOutpre:BN_Fmt``/``BYT_Or`` set them (the encoding stays ASCIi
        if it is)."""
        msb = (not self.binary.startswith("S")) if msb_first is None else msb_first
        if floating or (floating is None and signed is None and self.floating):
            binary = FLOATS[0] if msb else FLOATS[1]
        else:
            was_signed = self.binary not in ("RPBinary", "SRPbinary")
            binary = BINARY[(was_signed if signed is None else signed, msb)]
        return replace(self, binary=binary, encoding="ASCIi" if self.encoding == "ASCIi" else binary)

    @property
    def unsigned(self) -> bool:
        return self.encoding in ("RPBinary", "SRPbinary")

    @property
    def floating(self) -> bool:
        """4-byte floats (FPBinary, SFPbinary), or ASCIi kept from them."""
        return self.binary in FLOATS

    @property
    def sent_width(self) -> int:
        """Bytes a point is sent in: 4 for floats, else DATa:WIDth."""
        return 4 if self.floating else self.width

    def span(self, points: int) -> tuple:
        """(first index, end index) of the points sent from a record of ``points``: points
        DATa:STARt to DATa:STOP, the two taken in order where STARt is the larger (the
        manuals: the scope swaps them), clamped to the record."""
        lo, hi = sorted((self.start, self.stop))
        first = min(max(lo, 1), points) - 1
        return first, max(min(hi, points), first + 1)


def sent_codes(codes: np.ndarray, sel: DataSelection) -> np.ndarray:
    """The codes CURVe? sends (int64): the selected points, widened and offset."""
    first, end = sel.span(codes.size)
    if sel.floating:
        return codes[first:end].astype(np.int64)
    out = codes[first:end].astype(np.int64) * (256 if sel.width == 2 else 1)
    return out + (1 << (8 * sel.width - 1)) if sel.unsigned else out


def curve_bytes(codes: np.ndarray, sel: DataSelection) -> bytes:
    """CURVe?'s answer without a header: ``c1,c2,...`` or a definite-length block."""
    values = sent_codes(codes, sel)
    if sel.encoding == "ASCIi":
        return ",".join(map(str, values.tolist())).encode()
    order = "<" if sel.encoding.startswith("S") else ">"
    kind = "f" if sel.floating else "u" if sel.unsigned else "i"
    return definite_block(values.astype(f"{order}{kind}{sel.sent_width}").tobytes())


def scaled(pre: Preamble, sel: DataSelection, combined: bool = False) -> tuple:
    """(YMULT, YOFF, YZERO) of the codes as sent, volts = YZERO + YMULT (code - YOFF).

    The TDS2000's definition (``combined`` False): YOFF the vertical position in digitizing
    levels (with the unsigned encodings' 2^(8 width - 1)), YZERO the offset. The MDO3000's and
    the 4 Series' (``combined``; their manuals, WFMOutpre:YZEro: "the combined vertical
    position and offset ... For this instrument family, the value of :YOFf is always 0.0"):
    YOFF 0 and YZERO = offset - YMULT x that YOFF, the same volts for every code."""
    factor = 256 if sel.width == 2 and not sel.floating else 1
    ymult = pre.y_multiplier / factor
    yoff = pre.y_offset * factor + ((1 << (8 * sel.width - 1)) if sel.unsigned else 0)
    if combined:
        return ymult, 0.0, pre.y_zero - ymult * yoff
    return ymult, yoff, pre.y_zero


def waveform_id(channel: str, pre: Preamble, coupling: str, volts_per_div: float, mode: str,
                p: Personality) -> str:
    """The Tek WFID: ``Ch1, DC coupling, 50.0mV/div, 10.0us/div, 2500 points, Sample mode``."""
    s_div = pre.x_increment * pre.points / 10
    return (f"Ch{channel[2:]}, {coupling} coupling, {p.per_div(volts_per_div, 'V')}/div, "
            f"{p.per_div(s_div, 's')}/div, {pre.points} points, {mode} mode")


def preamble_fields(pre: Preamble, sel: DataSelection, wfid: str, p: Personality) -> Fields:
    """The model's preamble (``WFMPre?`` 16 fields, ``WFMOutpre?`` 22) for the bytes sent."""
    first, end = sel.span(pre.points)
    ymult, yoff, yzero = scaled(pre, sel, p.combined_offset)
    binary = sel.encoding != "ASCIi"
    values = {
        "BYT_Nr": str(sel.sent_width), "BIT_Nr": str(8 * sel.sent_width),
        "ENCdg": (Word("BINary" if binary else "ASCIi") if p.engineering else "BIN" if binary else "ASC"),
        "BN_Fmt": Word("FP" if sel.floating else "RP" if sel.binary in ("RPBinary", "SRPbinary") else "RI"),
        "BYT_Or": Word("LSB" if sel.binary.startswith("S") else "MSB"),
        "NR_Pt": str(end - first), "WFId": f'"{wfid}"', "PT_Fmt": Word("Y"),
        "XINcr": p.number(pre.x_increment), "PT_Off": "0",
        "XZEro": p.number(pre.x_zero + first * pre.x_increment), "XUNit": '"s"',
        "YMUlt": p.number(ymult), "YZEro": p.number(yzero), "YOFf": p.number(yoff),
        "YUNit": f'"{p.y_unit}"', "PT_ORder": Word("LINEAR"), "DOMain": Word("TIMe"),
        "ASC_Fmt": "FLOAT" if sel.floating else "INTEGER",  # what ASCIi sends: the codes as integers (or floats)
        "WFMTYpe": Word("ANALOG"), "CENTERFREQuency": p.number(0.0), "SPAN": p.number(0.0),
        "REFLevel": p.number(0.0)}
    return Fields(tuple((name, values[name]) for name in p.preamble_fields))
