"""What kind of scope file a file is, from its first bytes (its content, not its name).

The rig reads Tektronix ISF, CSV and WFM files. Every other maker's format is named in a
one-line refusal, so that a user who hands over a LeCroy or Rigol file learns what it is
and what the rig reads, instead of a parse error from deep inside a reader. The
signatures are those the makers' own programmer manuals give (and RigolWFM's detector
uses): LeCroy's WAVEDESC block, Tektronix's byte-order word and ":WFM#00n" version string,
Keysight's "AG" cookie and Infiniium HDF5 groups, Tektronix DPO5000/7000 HDF5 datasets,
Rigol's 0xA5A5 / 0xA1A5 / "RG0n" magics, DHO zlib blocks and CSV title rows, Siglent's
channel-on flags, volt/div records and "Analog:" tags, PicoScope's zip container and CSV
title/units rows, Yokogawa's ASCII keys, R&S's XML header (its eRS_
enumerations) and .Wfm.bin payload header (format code and record length that match the
file's size).
"""
from __future__ import annotations

import re
import struct
from pathlib import Path

from ..errors import InstrumentError

READABLE = "the rig reads Tektronix ISF, CSV and WFM files"
_UNITS_ROW = re.compile(rb"^\s*Second,\s*Volt", re.M)  # Rigol's DS1000B/D/E and Siglent's SDS CSV units row
HEAD_BYTES = 4096

# (name of the format, test on the first bytes); the first match wins
_FOREIGN = (
    ("a LeCroy .trc waveform", lambda h: b"WAVEDESC" in h[:64]),
    ("a Keysight/Agilent .bin waveform", lambda h: h[:2] == b"AG" and h[2:4].isdigit()),
    ("a Rigol .bin waveform", lambda h: h[:4] in (b"RG01", b"RG02", b"RG03")),
    ("a Rigol .wfm waveform", lambda h: h[:2] in (b"\xa5\xa5", b"\xa1\xa5", b"\x01\xff")),
    ("a Rigol DHO800/DHO1000 .wfm waveform (zlib-compressed blocks)", lambda h: _rigol_dho_wfm(h)),  # below
    ("a Yokogawa .wfm/.wvf waveform", lambda h: b"$PublicInfo" in h or all(
        k in h for k in (b"NR_PT:", b"XIN:", b"YMU:"))),
    # the .bin metadata of an R&S .bin / .Wfm.bin pair: XML with the eRS_ enumerations
    ("a Rohde & Schwarz waveform (.bin XML header)", lambda h: h.lstrip().startswith(b"<?xml") and (
        b"RohdeSchwarz" in h or b"eRS_" in h)),
    ("a Siglent SDS .bin waveform", lambda h: _siglent_bin(h)),  # defined below
    ("a zip archive (PicoScope .psdata / .pssettings files are zip archives)", lambda h: h[:4] == b"PK\x03\x04"),
    # DS1000Z/DS2000/DS4000: "X,CH1,...,Start,Increment," or, without the X column,
    # "CH1,CH2,Start,Increment,"; DS1000B/D/E: "X,CH1,CH2," or "Time,X(CH1),X(CH2)," then the
    # units row "Second,Volt,Volt,"
    ("a Rigol CSV export", lambda h: re.match(
        rb"\s*(X,)?(CH\d,|D\d+,|MATH\d?,)+\s*Start,Increment", h) is not None or re.match(
        rb"\s*(X|Time),((CH\d|X\(CH\d\)),?)+\s*\r?\n\s*Second,", h) is not None),
    ("a Keysight/Agilent CSV export", lambda h: re.match(rb"\s*x-axis,\d", h) is not None),
    # Siglent SDS: "Record Length,Analog:1400,", ..., then "Second,Volt,"
    ("a Siglent CSV export", lambda h: _siglent_csv(h)),  # defined below
    # a "Second,Volt" units row under a title row that names no maker: Rigol's DS1000B/D/E and
    # Siglent's SDS exports both write one
    ("a CSV export with a 'Second,Volt' units row (a Rigol DS1000B/D/E or Siglent SDS layout)",
     lambda h: _UNITS_ROW.search(h) is not None),
    # LeCroy WaveStudio / X-Stream: "LECROYWS...", "Segments,1,SegmentSize,...", then "Time,Ampl"
    ("a LeCroy CSV export", lambda h: h.lstrip().upper().startswith(b"LECROY") or re.search(
        rb"^\s*Segments,.*\r?\n(.*\r?\n){0,4}\s*Time,\s*Ampl", h, re.M) is not None),
    # PicoScope 6/7: "Time,Channel A,Channel B" then the units "(ms),(V),(mV)"
    ("a PicoScope CSV export", lambda h: re.match(
        rb"\s*Time,Channel [A-H](,Channel [A-H])*\s*\r?\n\s*\((s|ms|us|\xb5s|\xc2\xb5s|ns|ps)\),\(", h) is not None),
    ("a semicolon-separated CSV with decimal commas (a spreadsheet's re-save? the rig reads the scope's own "
     "CSV, comma-separated with decimal points)", lambda h: _decimal_comma_csv(h)),
)


def _siglent_csv(head: bytes) -> bool:
    """Siglent's CSV header: its values tagged "Analog:" (a "Second,Volt" units row alone
    is no maker's: Rigol's DS1000B/D/E write one too)."""
    return re.search(rb"^\s*(Record Length|Sample Interval),\s*Analog:", head, re.M) is not None


# Rigol DHO800/DHO1000 .wfm (RigolWFM's description of the layout): a 24-byte file header,
# then blocks of a 12-byte header (id, type, decompressed size, compressed size, content
# length: uint16 each, and a reserved one) and their content, zlib-compressed
_DHO_BLOCK, _DHO_CONTENT = 24, 36


def _rigol_dho_wfm(head: bytes) -> bool:
    if len(head) < _DHO_CONTENT + 2:
        return False
    _, _, _, compressed, length, _ = struct.unpack_from("<6H", head, _DHO_BLOCK)
    cmf, flg = head[_DHO_CONTENT], head[_DHO_CONTENT + 1]
    return 0 < compressed == length and cmf == 0x78 and (cmf * 256 + flg) % 31 == 0  # RFC 1950's header check


def _decimal_comma_csv(head: bytes) -> bool:
    """Rows of numbers with decimal commas separated by semicolons ("-0,25;1,5E-3"), as a
    spreadsheet in a European locale saves a CSV."""
    rows = re.findall(rb"^\s*[-+]?\d+,\d+(?:[eE][-+]?\d+)?\s*;\s*[-+]?\d+(?:,\d+)?", head, re.M)
    return len(rows) >= 2
# Siglent SDS1000X-E (and later revisions'): four int32 channel-on flags (0/1, one or more
# on), then each channel's volt/div as a 'data with unit' record: float64 value, uint32
# magnitude (0..16), uint32 unit (0..23)
_SIGLENT_FLAGS, _SIGLENT_VDIV, _SIGLENT_RECORD = 0x00, 0x10, 16


def _siglent_bin(head: bytes) -> bool:
    if len(head) < _SIGLENT_VDIV + 4 * _SIGLENT_RECORD:
        return False
    flags = struct.unpack_from("<4I", head, _SIGLENT_FLAGS)
    if not (set(flags) <= {0, 1} and any(flags)):
        return False
    for k in range(4):
        value, magnitude, unit = struct.unpack_from("<dII", head, _SIGLENT_VDIV + k * _SIGLENT_RECORD)
        if not (0 < value < 1e6 and magnitude <= 16 and unit <= 23):
            return False
    return True


# R&S .Wfm.bin payload: uint32 format code (0 int8, 1 int16, 4 float32, 6 x/y float32
# pairs), uint32 record length, then record length x bytes per value x channels (1 to 4)
_RS_WIDTH = {0: 1, 1: 2, 4: 4, 6: 8}


def _rs_payload(head: bytes, size: int) -> bool:
    if len(head) < 8:
        return False
    code, length = struct.unpack_from("<2I", head, 0)
    return code in _RS_WIDTH and length > 0 and any(size - 8 == length * _RS_WIDTH[code] * k for k in (1, 2, 3, 4))


def _hdf5_kind(path: Path) -> str:
    """What an HDF5 file is: a Keysight Infiniium waveform ('Waveforms' or 'Frame' group),
    a Tektronix DPO5000/7000 one (root datasets Data, Spacing, StartTime), or another HDF5
    file (a rig archive is read by the archive commands, not as a scope file)."""
    import h5py

    try:
        with h5py.File(path, "r") as f:
            if "Waveforms" in f or "Frame" in f:
                return "a Keysight Infiniium HDF5 waveform"
            if all(isinstance(f.get(k), h5py.Dataset) for k in ("Data", "Spacing", "StartTime")):
                return ("a Tektronix DPO5000/DPO7000 HDF5 waveform (float volts: Data, Spacing, StartTime; save "
                        "it from the scope as .isf or .csv)")
    except OSError:
        pass
    return "an HDF5 file (a rig archive? use rig analyze/verify/ls on .h5 files)"


BOM = b"\xef\xbb\xbf"  # UTF-8 byte-order mark, which some tools put before a CSV's first row


def tektronix_kind(head: bytes) -> str | None:
    """'isf', 'wfm' or 'csv' when the first bytes are a Tektronix file of that kind (a CSV
    after a UTF-8 byte-order mark too)."""
    head = head.removeprefix(BOM)
    if len(head) > 10 and head[0] in (0x0F, 0xF0) and head[1] in (0x0F, 0xF0) and head[3:7] == b"WFM#":
        return "wfm"
    if b"LLWFM" in head[:8]:
        return "wfm"
    if re.search(rb":CURV(?:E)?\s+#", head) or re.match(rb"\s*:?(WFMP|WFMPRE|WFMO|WFMOUTPRE):", head):
        return "isf"
    if _tek_csv(head):
        return "csv"
    return None


def _tek_csv(head: bytes) -> bool:
    """The header rows of either Tektronix CSV layout, or a TIME,CHn title row."""
    try:
        text = head.decode("ascii")
    except UnicodeDecodeError:
        return False
    if _siglent_csv(head) or _UNITS_ROW.search(head):
        return False  # Siglent's header rows have Tektronix's names; a units row is no Tektronix layout
    first = [line.split(",")[0].strip() for line in text.splitlines()[:40]]
    known = {"Model", "Firmware Version", "Record Length", "Sample Interval", "Point Format", "Waveform Type",
             "Horizontal Units", "Trigger Point", "Source", "Vertical Units", "Label", "TIME"}
    return sum(f in known for f in first) >= 2


def identify(path) -> str:
    """'isf', 'wfm' or 'csv' for a Tektronix file; otherwise InstrumentError in one line
    naming what the file is (another maker's format, or not a scope file at all)."""
    path = Path(path)
    if path.exists() and not path.is_file():  # a folder, a named pipe, a device: opening one may block
        what = "a folder" if path.is_dir() else "not a regular file (a named pipe, a socket or a device)"
        raise InstrumentError(f"{path}: {what}, not a scope file; {READABLE}")
    with open(path, "rb") as fh:
        head = fh.read(HEAD_BYTES)
    if not head.strip():
        raise InstrumentError(f"{path}: empty file, not a scope record ({READABLE})")
    kind = tektronix_kind(head)
    if kind:
        return kind
    if head[:8] == b"\x89HDF\r\n\x1a\n":
        raise InstrumentError(f"{path}: {_hdf5_kind(path)}; {READABLE}")
    for name, test in _FOREIGN:
        if test(head):
            raise InstrumentError(f"{path}: {name}; {READABLE}")
    if _rs_payload(head, path.stat().st_size):
        raise InstrumentError(f"{path}: a Rohde & Schwarz .Wfm.bin waveform payload; {READABLE}")
    text = b"\0" not in head[:512]
    what = "a text file in no scope format the rig knows" if text else "a binary file in no scope format the rig knows"
    raise InstrumentError(f"{path}: {what}; {READABLE}")
