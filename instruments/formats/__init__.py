"""Scope file formats: Tektronix ISF (binary) and Tektronix CSV, by file extension."""
from pathlib import Path

from ..errors import InstrumentError
from ..records import ScopeRecord
from .isf import read_isf, write_isf
from .tek_csv import read_csv, write_csv

WRITERS = {"isf": write_isf, "csv": write_csv}
READERS = {".isf": read_isf, ".csv": read_csv}


def read_record(paths) -> ScopeRecord:
    """Every waveform in scope files (the channels of one shot, in file order). A channel
    name met twice is kept as NAME@file-stem."""
    waves = {}
    for path in map(Path, paths):
        reader = READERS.get(path.suffix.lower())
        if reader is None:
            raise InstrumentError(f"{path}: cannot read {path.suffix or 'extensionless'} files as "
                                  f"scope records (known: {', '.join(READERS)})")
        for w in reader(path):
            waves[w.channel if w.channel not in waves else f"{w.channel}@{path.stem}"] = w
    return ScopeRecord(waves, True)
