"""What kind of scope file a file is, from its first bytes (its content, not its name).

The rig reads Tektronix ISF, CSV and WFM files. Every other maker's format is named in a
one-line refusal, so that a user who hands over a LeCroy or Rigol file learns what it is
and what the rig reads, instead of a parse error from deep inside a reader. The
signatures are those the makers' own programmer manuals give (and RigolWFM's detector
uses): LeCroy's WAVEDESC block, Tektronix's byte-order word and ":WFM#00n" version string,
Keysight's "AG" cookie, Rigol's 0xA5A5 / 0xA1A5 / "RG0n" magics, Yokogawa's ASCII keys.
"""
from __future__ import annotations

import re
from pathlib import Path

from ..errors import InstrumentError

READABLE = "the rig reads Tektronix ISF, CSV and WFM files"
HEAD_BYTES = 4096

# (name of the format, test on the first bytes); the first match wins
_FOREIGN = (
    ("a LeCroy .trc waveform", lambda h: b"WAVEDESC" in h[:64]),
    ("a Keysight/Agilent .bin waveform", lambda h: h[:2] == b"AG" and h[2:4].isdigit()),
    ("a Rigol .bin waveform", lambda h: h[:4] in (b"RG01", b"RG02", b"RG03")),
    ("a Rigol .wfm waveform", lambda h: h[:2] in (b"\xa5\xa5", b"\xa1\xa5", b"\x01\xff")),
    ("a Yokogawa .wfm/.wvf waveform", lambda h: b"$PublicInfo" in h or all(
        k in h for k in (b"NR_PT:", b"XIN:", b"YMU:"))),
    ("a Rohde & Schwarz waveform", lambda h: h.lstrip().startswith(b"<?xml") and b"RohdeSchwarz" in h),
    ("an HDF5 file (a rig archive? use rig analyze/verify/ls on .h5 files)",
     lambda h: h[:8] == b"\x89HDF\r\n\x1a\n"),
    ("a Rigol CSV export", lambda h: re.match(rb"\s*X,(CH\d,|D\d+,|MATH\d?,)+.*Start,Increment", h) is not None),
    ("a Keysight/Agilent CSV export", lambda h: re.match(rb"\s*x-axis,\d", h) is not None),
)


def tektronix_kind(head: bytes) -> str | None:
    """'isf', 'wfm' or 'csv' when the first bytes are a Tektronix file of that kind."""
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
    first = [line.split(",")[0].strip() for line in text.splitlines()[:40]]
    known = {"Model", "Firmware Version", "Record Length", "Sample Interval", "Point Format", "Waveform Type",
             "Horizontal Units", "Trigger Point", "Source", "Vertical Units", "Label", "TIME"}
    return sum(f in known for f in first) >= 2


def identify(path) -> str:
    """'isf', 'wfm' or 'csv' for a Tektronix file; otherwise InstrumentError in one line
    naming what the file is (another maker's format, or not a scope file at all)."""
    path = Path(path)
    with open(path, "rb") as fh:
        head = fh.read(HEAD_BYTES)
    if not head.strip():
        raise InstrumentError(f"{path}: empty file, not a scope record ({READABLE})")
    kind = tektronix_kind(head)
    if kind:
        return kind
    for name, test in _FOREIGN:
        if test(head):
            raise InstrumentError(f"{path}: {name}; {READABLE}")
    text = b"\0" not in head[:512]
    what = "a text file in no scope format the rig knows" if text else "a binary file in no scope format the rig knows"
    raise InstrumentError(f"{path}: {what}; {READABLE}")
