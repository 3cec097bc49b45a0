"""Scope file formats: Tektronix ISF (binary), Tektronix CSV and Tektronix WFM (through
Tektronix's tm_data_types, the ``wfm`` extra). A file's format is told from its content
(``sniff.identify``), not its name; other makers' files are refused naming their format."""
from pathlib import Path

from ..errors import InstrumentError
from ..records import ScopeRecord
from .isf import read_isf, write_isf
from .sniff import identify
from .tek_csv import read_csv, write_csv
from .tek_wfm import read_wfm

WRITERS = {"isf": write_isf, "csv": write_csv}
READERS = {"isf": read_isf, "csv": read_csv, "wfm": read_wfm}


def read_waveforms(path) -> list:
    """Every waveform in one Tektronix scope file, whatever its name says."""
    return READERS[identify(path)](path)


def read_record(paths) -> ScopeRecord:
    """Every waveform in scope files (the channels of one shot, in file order). A channel
    name met twice is kept as NAME@file-stem."""
    waves = {}
    for path in map(Path, paths):
        for w in read_waveforms(path):
            waves[w.channel if w.channel not in waves else f"{w.channel}@{path.stem}"] = w
    return ScopeRecord(waves, True)


def check_one_time_base(record: ScopeRecord) -> None:
    """InstrumentError in one line unless every channel of ``record`` has the first one's
    time base (points, sample interval, first sample's time), as the analysis of one shot
    needs; it names the two files (or channels) and their time bases."""
    first, *others = record.waveforms.values()
    for w in others:
        if _time_base(w) != _time_base(first):
            raise InstrumentError(f"{_origin(first)} and {_origin(w)} have different time bases: "
                                  f"{_said(first)}, {_said(w)}; the channels of one shot share one time base")


def _time_base(w) -> tuple:
    return w.preamble.points, w.preamble.x_increment, w.preamble.x_zero


def _origin(w) -> str:
    return f"{w.preamble.extra.get('source', 'the record')} ({w.channel})"


def _said(w) -> str:
    n, dt, t0 = _time_base(w)
    return f"{n} points at {dt:.6g} s from {t0:.9g} s"
