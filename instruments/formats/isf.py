"""Tektronix ISF: a WFMPRE text header then a binary CURVE block.

Header (full keywords, as DPO/TDS scopes write them):
  :WFMPRE:BYT_NR 1;BIT_NR 8;ENCDG BIN;BN_FMT RI;BYT_OR MSB;NR_PT n;WFID "...";PT_FMT Y;
  XUNIT "s";XINCR dt;XZERO t0;PT_OFF 0;YUNIT "V";YMULT m;YOFF o;YZERO z;:CURVE #<d><len><bytes>
PT_OFF is written 0 with XZERO the first sample's time, so readers that use
t = XZERO + XINCR (n - PT_OFF) and readers that ignore PT_OFF agree.

The reader takes what real scopes write: full (":WFMPRE:BYT_NR") or abbreviated
(":WFMP:BYT_N") keywords, 8- or 16-bit, either byte order, binary or ASCII curves
(ENCDG ASC: comma-separated codes; a header whose encoding contradicts its curve is
refused), sample (Y) or envelope (ENV) records, and several header+curve records back to
back in one file (each is returned).
"""
from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from ..errors import InstrumentError
from ..files import atomic_writes
from ..rails import flagged
from ..records import Preamble, Waveform
from .checks import analog_only, bandwidth, channel_name, screen, time_axis, vertical_unit

# every spelling real scopes use, long and short, to one canonical key
_ALIASES = {"BYT_NR": "BYT_NR", "BYT_N": "BYT_NR", "BIT_NR": "BIT_NR", "BIT_N": "BIT_NR",
            "ENCDG": "ENCDG", "ENC": "ENCDG", "BN_FMT": "BN_FMT", "BN_F": "BN_FMT",
            "BYT_OR": "BYT_OR", "BYT_O": "BYT_OR", "WFID": "WFID", "WFI": "WFID",
            "NR_PT": "NR_PT", "NR_P": "NR_PT", "PT_FMT": "PT_FMT", "PT_F": "PT_FMT",
            "XUNIT": "XUNIT", "XUN": "XUNIT", "XINCR": "XINCR", "XIN": "XINCR",
            "XZERO": "XZERO", "XZE": "XZERO", "PT_OFF": "PT_OFF", "PT_O": "PT_OFF",
            "YUNIT": "YUNIT", "YUN": "YUNIT", "YMULT": "YMULT", "YMU": "YMULT",
            "YOFF": "YOFF", "YOF": "YOFF", "YZERO": "YZERO", "YZE": "YZERO",
            "FILTERF": "FILTERF", "FILTERFREQ": "FILTERF",  # the channel's filter (bandwidth) frequency, Hz
            # what the record is (DPO/MDO/4/5/6 Series): TIME or FREQUENCY; ANALOG, DIGITAL, RF_TD, RF_FD;
            # the frames of a FastFrame set; the screen (V/div, divisions)
            "DOMAIN": "DOMAIN", "DOM": "DOMAIN", "WFMTYPE": "WFMTYPE", "WFMTYP": "WFMTYPE",
            "NR_FR": "NR_FR", "VSCALE": "VSCALE", "VSCA": "VSCALE", "VPOS": "VPOS", "VOFFSET": "VOFFSET",
            "VOFFS": "VOFFSET"}
_REQUIRED = ("BYT_NR", "NR_PT", "XINCR", "XZERO", "YMULT", "YOFF", "YZERO")
_CURVE = re.compile(rb":CURV(?:E)?\s+")
# the end of an ASCII curve: the line's end, or the next record's header
_ASCII_END = re.compile(rb"[\r\n]|;?:(?:WFMP|WFMPRE|WFMO|WFMOUTPRE):")
# the source named at the start of WFID: "Ch2, DC coupling, ...", "Math, ...", "Math1 ...", "Ref3"
_CHANNEL = re.compile(r"^\s*(ch(?=\s*\d)|math|ref)\s*(\d*)", re.IGNORECASE)


def _num(x: float) -> str:
    return f"{x:.10E}"


def waveform_id(w: Waveform) -> str:
    """The WFID a scope writes, naming the source first ("CH1, DC coupling, ..."): the
    record's own where it names its channel, else the channel before it."""
    wfid = w.preamble.waveform_id.replace('"', "'")
    return wfid if wfid.upper().replace(" ", "").startswith(w.channel.upper()) else \
        ", ".join(filter(None, (w.channel, wfid)))


def isf_bytes(w: Waveform) -> bytes:
    """The bytes of an ISF file holding one channel's codes."""
    p = w.preamble
    nbytes = p.byte_count
    codes = np.asarray(w.codes).astype(">i1" if nbytes == 1 else ">i2")
    header = (f":WFMPRE:BYT_NR {nbytes};BIT_NR {8 * nbytes};ENCDG BIN;BN_FMT RI;BYT_OR MSB;"
              f"NR_PT {p.points};WFID \"{waveform_id(w)}\";PT_FMT {p.point_format};XUNIT \"{p.x_unit}\";"
              f"XINCR {_num(p.x_increment)};XZERO {_num(p.x_zero)};PT_OFF 0;"
              f"YUNIT \"{p.y_unit}\";YMULT {_num(p.y_multiplier)};YOFF {_num(p.y_offset)};"
              f"YZERO {_num(p.y_zero)};:CURVE ")
    data = codes.tobytes()
    count = str(len(data))
    return header.encode("ascii") + f"#{len(count)}{count}".encode("ascii") + data + b"\n"


def write_isf(waveforms: dict, directory, stem: str) -> list:
    """Write one ISF file per channel, ``<stem>_<CH>.isf``, all or none of them
    (instruments.files); returns the paths."""
    return atomic_writes({Path(directory) / f"{stem}_{ch}.isf": _bytes_writer(isf_bytes(w))
                          for ch, w in waveforms.items()})


def _bytes_writer(data: bytes):
    return lambda tmp: Path(tmp).write_bytes(data)


def read_isf(path) -> list:
    """Every record in a Tektronix ISF file, as Waveforms (volts = YZERO + YMULT (code - YOFF)).

    Raises InstrumentError naming the file for a missing header field, a non-numeric
    value, a byte count that disagrees with the header, or a truncated curve block.
    """
    path = Path(path)
    data = path.read_bytes()
    out: list[Waveform] = []
    pos = 0
    while pos < len(data) and data[pos:].strip():
        m = _CURVE.search(data, pos)
        if m is None:
            raise InstrumentError(f"{path}: no :CURVE block after byte {pos} (not an ISF file?)")
        header = _parse_header(data[pos:m.start()], path)
        analog_only(path, waveform_type=header.get("WFMTYPE", ""), domain=header.get("DOMAIN", ""),
                    source=header.get("WFID", ""), number_format=header.get("BN_FMT", ""),
                    frames=header.get("NR_FR", ""))
        time_axis(path, "XUNIT", header.get("XUNIT", "s"))
        ascii_header = header.get("ENCDG", "BIN").upper().startswith("ASC")
        binary_block = data[m.end():m.end() + 1] == b"#"
        if ascii_header == binary_block:
            said = (f"ENCDG {header['ENCDG']} (ASCII codes) over a binary '#' block" if ascii_header
                    else f"ENCDG {header.get('ENCDG', 'BIN (not given)')} (binary) over a curve that is no '#' block")
            raise InstrumentError(f"{path}: the header says {said} at byte {m.end()}: the header and the curve "
                                  f"contradict each other (an ASCII curve is comma-separated codes, a binary one "
                                  f"#<digits><length><bytes>)")
        codes, pos = (_read_ascii_curve(data, m.end(), header, path) if ascii_header
                      else _read_curve(data, m.end() + 1, header, path))
        out.append(_waveform(header, codes, path, len(out)))
        while pos < len(data) and data[pos:pos + 1] in (b"\n", b"\r", b" "):
            pos += 1
    if not out:
        raise InstrumentError(f"{path}: empty file")
    return out


def _parse_header(raw: bytes, path) -> dict:
    try:
        text = raw.decode("ascii")
    except UnicodeDecodeError:
        raise InstrumentError(f"{path}: the header is not ASCII text (not an ISF file?)") from None
    fields: dict[str, str] = {}
    for item in text.split(";"):
        item = re.sub(r"^(:?[A-Z]+:)+", "", item.strip())  # drop :WFMPRE: / :WFMP:
        if not item:
            continue
        key, _, value = item.partition(" ")
        canon = _ALIASES.get(key.upper())
        if canon:
            value = value.strip().strip('"')
            if canon in fields and fields[canon] != value:
                raise InstrumentError(f"{path}: header field {canon} given twice ({fields[canon]!r} and {value!r}): "
                                      f"the header contradicts itself")
            fields[canon] = value
    missing = [k for k in _REQUIRED if k not in fields]
    if missing:
        raise InstrumentError(f"{path}: header field(s) missing: {', '.join(missing)}")
    return fields


def _number(header, key, path, kind=float):
    """A header field's value: a finite number (a whole one where ``kind`` is int)."""
    try:
        value = float(header[key])
    except ValueError:
        raise InstrumentError(f"{path}: header field {key} = {header[key]!r} is not a number") from None
    if not np.isfinite(value) or (kind is int and not value.is_integer()):
        raise InstrumentError(f"{path}: {key} = {value!r}: the header field must be a finite "
                              f"{'whole ' if kind is int else ''}number")
    return int(value) if kind is int else value


def _read_curve(data: bytes, at: int, header: dict, path):
    ndig = data[at:at + 1]
    if not ndig.isdigit() or ndig == b"0":
        raise InstrumentError(f"{path}: malformed curve block length at byte {at}")
    n = int(ndig)
    count_text = data[at + 1:at + 1 + n]
    if len(count_text) < n or not count_text.isdigit():
        raise InstrumentError(f"{path}: malformed curve block length at byte {at}")
    count = int(count_text)
    start = at + 1 + n
    nbytes = _number(header, "BYT_NR", path, int)
    points = _number(header, "NR_PT", path, int)
    if points < 2:
        raise InstrumentError(f"{path}: NR_PT = {points}: a record needs at least 2 points (one has no time base)")
    if nbytes not in (1, 2):
        raise InstrumentError(f"{path}: BYT_NR = {nbytes}: only 1 or 2 bytes per point are defined")
    if count != points * nbytes:
        raise InstrumentError(f"{path}: the curve block holds {count} bytes but the header says "
                              f"{points} points x {nbytes} bytes = {points * nbytes}")
    if len(data) - start < count:
        raise InstrumentError(f"{path}: truncated curve block: {len(data) - start} of {count} bytes present")
    order = ">" if header.get("BYT_OR", "MSB").upper() == "MSB" else "<"
    fmt = header.get("BN_FMT", "RI").upper()
    if fmt not in ("RI", "RP"):
        raise InstrumentError(f"{path}: BN_FMT = {fmt}: binary codes are RI (signed) or RP (unsigned)")
    dtype = np.dtype(f"{order}{'i' if fmt == 'RI' else 'u'}{nbytes}")
    codes = np.frombuffer(data, dtype=dtype, count=points, offset=start).astype(dtype.newbyteorder("="))
    return codes, start + count


def _read_ascii_curve(data: bytes, at: int, header: dict, path):
    """The codes of an ASCII curve (ENCDG ASCii: comma-separated integers, as the
    Tektronix programmer manuals define CURVe? with that encoding) and where it ends."""
    end = _ASCII_END.search(data, at)
    stop = end.start() if end else len(data)
    text = data[at:stop].decode("ascii", "replace").strip()
    nbytes = _number(header, "BYT_NR", path, int)
    points = _number(header, "NR_PT", path, int)
    if nbytes not in (1, 2):
        raise InstrumentError(f"{path}: BYT_NR = {nbytes}: only 1 or 2 bytes per point are defined")
    cells = [c.strip() for c in text.split(",")]
    if not all(re.fullmatch(r"[-+]?\d+", c) for c in cells):
        bad = next(c for c in cells if not re.fullmatch(r"[-+]?\d+", c))
        raise InstrumentError(f"{path}: the ASCII curve holds {bad[:20]!r}, not a whole-number code")
    if len(cells) != points:
        raise InstrumentError(f"{path}: the ASCII curve holds {len(cells)} codes but the header says NR_PT = {points}")
    if points < 2:
        raise InstrumentError(f"{path}: NR_PT = {points}: a record needs at least 2 points (one has no time base)")
    unsigned = header.get("BN_FMT", "RI").upper() == "RP"
    dtype = np.dtype(f"{'u' if unsigned else 'i'}{nbytes}")
    codes = np.array([int(c) for c in cells], dtype=np.int64)
    info = np.iinfo(dtype)
    if codes.min() < info.min or codes.max() > info.max:
        raise InstrumentError(f"{path}: an ASCII code of {codes.min() if codes.min() < info.min else codes.max()} "
                              f"does not fit BYT_NR = {nbytes}{', BN_FMT RP' if unsigned else ''} "
                              f"({info.min} to {info.max})")
    return codes.astype(dtype), stop


def _signed(codes: np.ndarray, y_offset: float) -> tuple:
    """(signed codes, YOFF) of the same volts: BN_FMT RP's unsigned codes c (0 .. 2^(8n) - 1)
    become c - 2^(8n-1) with YOFF moved by as much, volts = YZERO + YMULT (code - YOFF)
    unchanged, so every record holds int8 or int16 codes as a scope's RI records do."""
    if codes.dtype.kind != "u":
        return codes, y_offset
    half = 1 << (8 * codes.dtype.itemsize - 1)
    signed = np.dtype(f"i{codes.dtype.itemsize}")
    return (codes.astype(np.int32) - half).astype(signed), y_offset - half


_VOLTS_PER_DIV = re.compile(r"([-+]?\d+(?:\.\d*)?(?:[eE][-+]?\d+)?)\s*(m|u|\u00b5|n)?V/div", re.IGNORECASE)
_PREFIX = {None: 1.0, "m": 1e-3, "u": 1e-6, "\u00b5": 1e-6, "n": 1e-9}


def _screen_of(h: dict, y_multiplier: float, y_offset: float, y_zero: float) -> dict:
    """The screen the header gives, as the CSV reader keeps it (checks.screen): VSCALE,
    VOFFSET and VPOS of a DPO/MSO header, else the V/div its WFID names ("50.00mV/div")
    with the offset and position the scaling implies: code 0 at the screen's centre, so the
    offset is YZERO and the position YOFF codes of V/div / YMULT codes a division."""
    if "VSCALE" in h:
        return screen(h["VSCALE"], h.get("VOFFSET"), h.get("VPOS"))
    m = _VOLTS_PER_DIV.search(h.get("WFID", ""))
    if m is None:
        return {}
    volts_per_div = float(m.group(1)) * _PREFIX[m.group(2) and m.group(2).lower()]
    return screen(volts_per_div, y_zero, y_offset * y_multiplier / volts_per_div if volts_per_div else 0)


def _waveform(h: dict, codes, path, index) -> Waveform:
    dx = _number(h, "XINCR", path)  # finite: _number refuses nan and inf
    if not dx > 0:
        raise InstrumentError(f"{path}: XINCR = {dx!r}: the sample interval must be a finite number > 0 s")
    x_unit = time_axis(path, "XUNIT", h.get("XUNIT", "s"))
    ymult = _number(h, "YMULT", path)
    if ymult == 0:
        raise InstrumentError(f"{path}: YMULT = {ymult!r}: the volts per code must be a finite number other than 0")
    nbytes = codes.dtype.itemsize
    codes, y_offset = _signed(codes, _number(h, "YOFF", path))
    if abs(y_offset) > 1 << (8 * nbytes):
        raise InstrumentError(f"{path}: YOFF = {h['YOFF']}: a code offset beyond the converter's range "
                              f"(+-{1 << (8 * nbytes)} for {nbytes} byte(s) a point): not this record's header")
    y_zero = _number(h, "YZERO", path)
    x0 = _number(h, "XZERO", path)
    pt_off = _number(h, "PT_OFF", path, int) if "PT_OFF" in h else 0
    first = x0 - dx * pt_off  # t = XZERO + XINCR (n - PT_OFF)
    trigger = pt_off if pt_off else int(np.clip(round(-first / dx), 0, codes.size - 1))
    wfid = h.get("WFID", "")
    m = _CHANNEL.match(wfid)
    name = f"{m.group(1).upper()}{m.group(2)}" if m else Path(path).stem  # no source named: the file
    name_in_file = name
    envelope = h.get("PT_FMT", "Y").upper() in ("ENV", "ENVELOPE")
    if index:
        name = f"{name}#{index + 1}"
    name = channel_name(name)
    pre = Preamble(points=codes.size, x_increment=dx, x_zero=first, trigger_index=trigger,
                   y_multiplier=ymult, y_offset=y_offset,
                   y_zero=y_zero, byte_count=codes.dtype.itemsize,
                   x_unit=x_unit, y_unit=vertical_unit(h.get("YUNIT")), waveform_id=wfid,
                   point_format="ENV" if envelope else "Y",
                   extra={"source": str(path), "record": index + 1, "name_in_file": name_in_file,
                          **bandwidth(h.get("FILTERF")), **_screen_of(h, ymult, y_offset, y_zero)})
    return flagged(Waveform(name, pre, codes=codes))
