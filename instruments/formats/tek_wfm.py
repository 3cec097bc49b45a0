"""Tektronix .wfm (WFM#001/002/003, the native files of DPO/MSO and 4/5/6 Series scopes),
read through RigolWFM, which parses the three layouts from their Kaitai descriptions.

(Tektronix's own tm_data_types reads these files too, but it pins numpy < 2 and
numba < 0.61, which the rig's stack cannot take; its values agree with RigolWFM's on
Tektronix's sample file: tests/instruments/test_realdata.py.)

The file's codes and its explicit dimension's scale and offset become the same Waveform
as an ISF record: volts = y_zero + y_multiplier * code with y_multiplier the file's volts
per code and y_zero its volts at code 0; time = x_zero + x_increment * n, x_zero the first
valid sample's time relative to the trigger (s). RigolWFM hands over float32 volts; the
codes are recovered exactly from them (the scale is the file's own). One analog record per
file; the file names no source channel, so the Waveform is called after its waveform label
or the file (made a name the archive stores; the name as given is kept in extra).

Before any parsing, the header fields at the fixed offsets of Tektronix's "Reference
Waveform File Format" (the same in WFM#001, #002 and #003) say what the file holds, and
what is not one analog record is refused by name: a digital waveform (data type 6), an IQ
record (interleaved I and Q samples, told by the IQ_ keys of its trailing tekmeta block),
a FastFrame set (set type 1, or more than one frame), any other data type than a vector,
and a record whose horizontal (implicit dimension) unit is not seconds (a spectrum), each
before the bytes per point, so that a refusal names what the record is.
"""
from __future__ import annotations

import re
import struct
from pathlib import Path

import numpy as np

from ..errors import InstrumentError
from ..rails import flagged
from ..records import Preamble, Waveform
from .checks import channel_name, time_axis

# static file info and waveform header offsets (bytes), Reference Waveform File Format
BYTES_PER_POINT = 15
WAVEFORM_LABEL = 40  # char[32]
FAST_FRAMES_MINUS_ONE = 72  # uint32
SET_TYPE = 78  # int32: 0 single waveform, 1 FastFrame
DATA_TYPE = 122  # int32: 2 vector (analog), 6 digital
VECTOR, DIGITAL, FASTFRAME = 2, 6, 1
DATA_TYPES = {0: "a scalar measurement", 1: "a scalar constant", 4: "an invalid-data record",
              5: "a waveform database (pixel map) record", DIGITAL: "a digital waveform"}
VERSIONS = (b":WFM#001", b":WFM#002", b":WFM#003")
_IQ_KEY = re.compile(rb"IQ_(centerFrequency|fftLength|rbw|span|windowType|sampleRate)")
_TEKMETA = b"tekmeta!"


def check_header(path, data: bytes) -> None:
    """InstrumentError in one line unless ``data`` (a WFM#00n file) holds one analog record."""
    if len(data) < DATA_TYPE + 4 or data[:2] not in (b"\x0f\x0f", b"\xf0\xf0"):
        return  # the legacy LLWFM files and short files are left to the parser's own checks
    order = "<" if data[:2] == b"\x0f\x0f" else ">"
    if data[2:10] not in VERSIONS:
        raise InstrumentError(f"{path}: WFM version string = {data[2:10]!r}: the rig reads "
                              f"{', '.join(v.decode() for v in VERSIONS)}")
    (frames,) = struct.unpack_from(f"{order}I", data, FAST_FRAMES_MINUS_ONE)
    (set_type,) = struct.unpack_from(f"{order}i", data, SET_TYPE)
    (data_type,) = struct.unpack_from(f"{order}i", data, DATA_TYPE)
    if data_type != VECTOR:
        what = DATA_TYPES.get(data_type, f"an unknown data type {data_type}")
        raise InstrumentError(f"{path}: {what} (WFM data type = {data_type}); the rig reads analog "
                              f"records (data type {VECTOR}, a vector of codes)")
    meta = data.find(_TEKMETA)
    if meta >= 0 and _IQ_KEY.search(data, meta):
        raise InstrumentError(f"{path}: an IQ waveform (interleaved I and Q samples, tekmeta IQ_ keys); "
                              f"the rig reads analog voltage records")
    if set_type == FASTFRAME or frames > 0:
        raise InstrumentError(f"{path}: a FastFrame waveform set ({frames + 1} frames, set type = {set_type}); "
                              f"the rig reads single-record files (save one frame)")
    time_axis(path, "WFM implicit dimension units", _horizontal_unit(data))
    if data[BYTES_PER_POINT] not in (1, 2):
        raise InstrumentError(f"{path}: WFM bytes per point = {data[BYTES_PER_POINT]}: the rig reads integer codes "
                              f"of 1 or 2 bytes (4 or 8 bytes: int32 or floating-point values)")


def read_wfm(path) -> list:
    """The analog record of a Tektronix .wfm file, as one Waveform (codes + scaling)."""
    from RigolWFM.wfm import Wfm

    path = Path(path)
    data = path.read_bytes()
    check_header(path, data)
    try:
        ch = Wfm.from_file(str(path), "TEK").channels[0]
    except Exception as exc:  # the library's own errors name no file
        detail = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise InstrumentError(f"{path}: not a readable Tektronix .wfm analog record ({detail})") from None
    volts, times = np.asarray(ch.volts, dtype=np.float64), np.asarray(ch.times, dtype=np.float64)
    scale, offset = float(ch.volt_scale), float(ch.volt_offset)
    if volts.size < 2 or not (np.isfinite(scale) and scale != 0):
        raise InstrumentError(f"{path}: a .wfm record of {volts.size} samples at {scale!r} V per code "
                              f"(needs >= 2 samples and a finite non-zero scale)")
    dx = float(times[1] - times[0])
    if not (np.isfinite(dx) and dx > 0):
        raise InstrumentError(f"{path}: sample interval {dx!r}: must be a finite number > 0 s")
    codes = np.rint((volts - offset) / scale)
    width = data[BYTES_PER_POINT]
    dtype = np.int8 if width == 1 else np.int16
    info = np.iinfo(dtype)
    if codes.min() < info.min or codes.max() > info.max:
        raise InstrumentError(f"{path}: codes outside {dtype.__name__} ({width} byte(s) per point): "
                              f"not an integer-coded analog record")
    x0 = float(times[0])
    name = _label(data) or path.stem
    pre = Preamble(points=volts.size, x_increment=dx, x_zero=x0,
                   trigger_index=int(np.clip(round(-x0 / dx), 0, volts.size - 1)),
                   y_multiplier=scale, y_offset=0.0, y_zero=offset, byte_count=np.dtype(dtype).itemsize,
                   extra={"source": str(path), "format": "Tektronix WFM", "name_in_file": name})
    return [flagged(Waveform(channel_name(name), pre, codes=codes.astype(dtype)))]


def _label(data: bytes) -> str:
    """The static file info's waveform label ('' where none is set)."""
    return data[WAVEFORM_LABEL:WAVEFORM_LABEL + 32].split(b"\0")[0].decode("ascii", "replace").strip()


def _horizontal_unit(data: bytes) -> str:
    """The implicit dimension's units through the documented layout (RigolWFM's Kaitai
    description of WFM#001/#002/#003); 's' where the file is a legacy LLWFM file."""
    from RigolWFM import (
        tektronix_wfm_001_be_wfm,
        tektronix_wfm_001_le_wfm,
        tektronix_wfm_002_be_wfm,
        tektronix_wfm_002_le_wfm,
    )

    if data[:2] not in (b"\x0f\x0f", b"\xf0\xf0"):
        return "s"
    layouts = {(True, True): tektronix_wfm_001_le_wfm.TektronixWfm001LeWfm,
               (True, False): tektronix_wfm_001_be_wfm.TektronixWfm001BeWfm,
               (False, True): tektronix_wfm_002_le_wfm.TektronixWfm002LeWfm,
               (False, False): tektronix_wfm_002_be_wfm.TektronixWfm002BeWfm}
    layout = layouts[(data[3:10] == b"WFM#001", data[:2] == b"\x0f\x0f")]
    try:
        units = layout.from_bytes(data).wfm_header.imp_dim1.units
    except Exception:  # noqa: BLE001 - a header the description cannot parse: the reader's own parse names it
        return "s"
    return units.split(b"\0")[0].decode("ascii", "replace")
