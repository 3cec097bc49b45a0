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
    waves = list(record.waveforms.values())
    for w in waves[1:]:
        a, b = waves[0].preamble, w.preamble
        if (a.points, a.x_increment, a.x_zero) != (b.points, b.x_increment, b.x_zero):
            def where(x):
                return f"{x.preamble.extra.get('source', 'the record')} ({x.channel})"

            def base(p):
                return f"{p.points} points at {p.x_increment:.6g} s from {p.x_zero:.9g} s"

            raise InstrumentError(f"{where(waves[0])} and {where(w)} have different time bases: {base(a)}, "
                                  f"{base(b)}; the channels of one shot share one time base")
