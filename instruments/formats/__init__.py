"""Scope file formats: Tektronix ISF (binary), Tektronix CSV and Tektronix WFM (through
RigolWFM, a core dependency). A file's format is told from its content
(``sniff.identify``), not its name; other makers' files are refused naming their format."""
from pathlib import Path

from ..errors import InstrumentError
from ..records import ScopeRecord, time_base_mismatch
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
    time base (records.time_base_mismatch: points, sample interval, first sample's time),
    as the analysis of one shot needs; it names the two files (or channels) and their time
    bases."""
    first, *others = record.waveforms.values()
    for w in others:
        mismatch = time_base_mismatch(first, w)
        if mismatch:
            raise InstrumentError(mismatch)
