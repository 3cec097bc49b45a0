"""Scope file formats: Tektronix ISF (binary), Tektronix CSV and Tektronix WFM (through
Tektronix's tm_data_types, the ``wfm`` extra). A file's format is told from its content
(``sniff.identify``), not its name; other makers' files are refused naming their format."""
from pathlib import Path

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
