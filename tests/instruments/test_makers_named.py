"""Other makers' files are named by their documented headers, each maker its own: a
"Second,Volt" units row is Rigol's DS1000B/D/E as much as Siglent's (named as either, never
as Siglent alone), Siglent's CSV tags its values "Analog:", a Rigol DHO .wfm is zlib blocks
after a 24-byte header, and a Tektronix DPO5000/7000 HDF5 file holds Data, Spacing and
StartTime datasets. Files built to each layout (the makers' manuals, RigolWFM's layout
descriptions); the real ones here are tests/instruments/test_realdata.py's."""
import struct
import zlib

import h5py
import numpy as np
import pytest

from instruments.errors import InstrumentError
from instruments.formats import identify, read_waveforms

ROWS = "".join(f"{k * 1e-6:.6e},{0.01 * k:.4e}\n" for k in range(40))
CASES = {
    # Rigol DS1000B (DS1204B): "Time,X(CH1),X(CH2)," / "Second,Volt,Volt,"
    "rigol_ds1204b.csv": (b"Time,X(CH1),X(CH2),\nSecond,Volt,Volt,\n" + ROWS.replace("\n", ",0.0,\n").encode(),
                          "a Rigol CSV export"),
    # Rigol DS1000E (DS1052E): "X,CH1," / "Second,Volt,"
    "rigol_ds1052e.csv": (b"X,CH1,\nSecond,Volt,\n" + ROWS.encode(), "a Rigol CSV export"),
    # Rigol DS1000Z: "X,CH1,Start,Increment," then the values row
    "rigol_ds1054z.csv": (b"X,CH1,Start,Increment,\nSequence,Volt,-2.0e-05,1.0e-06\n" + ROWS.encode(),
                          "a Rigol CSV export"),
    # Siglent SDS: the header's values tagged "Analog:"
    "siglent.csv": (b"Record Length,Analog:40,\nSample Interval,Analog:1.00E-06,\nSecond,Volt,\n" + ROWS.encode(),
                    "a Siglent CSV export"),
    # a units row under a title row that names no maker
    "units_only.csv": (b"Source,CH1\nSecond,Volt,\n" + ROWS.encode(), "(a Rigol DS1000B/D/E or Siglent SDS layout)"),
    "keysight.csv": (b"x-axis,1,2\nsecond,Volt,Volt\n" + ROWS.encode(), "a Keysight/Agilent CSV export"),
    # Rigol DHO800/1000 .wfm: 24-byte header, then a block header and zlib-compressed content
    "rigol_dho.wfm": (bytes(24)
                      + (lambda c: struct.pack("<6H", 1, 2, 64, len(c), len(c), 0) + c)(zlib.compress(bytes(64)))
                      + bytes(12), "a Rigol DHO800/DHO1000 .wfm waveform"),
}


@pytest.mark.parametrize("name", list(CASES))
def test_each_maker_is_named_by_its_own_header(tmp_path, name):
    data, maker = CASES[name]
    path = tmp_path / name
    path.write_bytes(data)
    with pytest.raises(InstrumentError) as err:
        read_waveforms(path)
    said = str(err.value)
    assert maker in said and said.startswith(str(path)) and "\n" not in said, said
    if name != "siglent.csv":
        assert "a Siglent CSV export" not in said, said


def test_a_tektronix_dpo5000_hdf5_file_is_named_as_one(tmp_path):
    path = tmp_path / "tek1.h5"
    with h5py.File(path, "w") as f:  # the DPO5204's layout: float32 volts and the time base
        f["Data"] = np.sin(np.arange(10000) / 50.0).astype(np.float32)
        f["Spacing"] = np.array([4e-10])
        f["StartTime"] = np.array([-2e-6])
    with pytest.raises(InstrumentError, match="a Tektronix DPO5000/DPO7000 HDF5 waveform") as err:
        identify(path)
    assert "rig archive" not in str(err.value)


def test_a_named_pipe_or_a_folder_is_refused_without_being_opened(tmp_path):
    """A named pipe given as a scope file had blocked the import forever (opening it waits
    for a writer); it is refused in one line, as a folder is. An alarm fails the test rather
    than hanging the suite, should it block again."""
    import os
    import signal

    pipe = tmp_path / "scope.isf"
    os.mkfifo(pipe)

    def blocked(signum, frame):
        raise AssertionError("reading a named pipe blocked")

    old = signal.signal(signal.SIGALRM, blocked)
    signal.alarm(20)
    try:
        for path, what in ((pipe, "not a regular file (a named pipe"), (tmp_path, "a folder, not a scope file")):
            with pytest.raises(InstrumentError, match=what.replace("(", r"\(")) as err:
                read_waveforms(path)
            assert str(err.value).startswith(str(path))
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)
