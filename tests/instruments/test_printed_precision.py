"""A CSV reader's time check is as tight as the file's printing allows, no tighter: a
TBS1000C prints its TIME column to four significant digits (``6.109e-05``), which round a
time by up to half a unit in its last digit, 0.16 of a sample at 3.2e-8 s. Files built to
that layout at every decade of the sample interval read on the header's time base; a time
moved past the bound the printed digits allow is refused, one moved to just within it
is not."""
import math

import numpy as np
import pytest

from instruments.errors import InstrumentError
from instruments.formats import read_waveforms
from instruments.formats.checks import printed_quanta, printed_quantum
from instruments.formats.csv_columns import TIME_TOLERANCE

POINTS = 2000
DECADES = range(-11, 0)  # sample intervals 3.2e-11 s ... 3.2e-1 s


def _tbs1000c(path, dt: float, times: list) -> None:
    """A TBS1102C's CSV: Model/Firmware rows, no Zero Index, TIME,CH1 in four digits."""
    head = ["Model,TBS1102C", "Firmware Version,v1.38", "", "Point Format,Y", "Horizontal Units,S",
            f"Horizontal Scale,{dt * POINTS / 16:g}", f"Sample Interval,{dt:g}", "Filter Frequency,2e+07",
            f"Record Length,{POINTS}", "Gating,0.0% to 100.0%", "Probe Attenuation,1", "Vertical Units,V",
            "Vertical Offset,0", "Vertical Scale,0.5", "Label,", "TIME,CH1"]
    volts = 0.02 * np.round(50 * np.sin(np.arange(POINTS) / 40.0)) / 50
    path.write_text("\n".join(head + [f"{t},{v:g}" for t, v in zip(times, volts)]) + "\n")


def _grid(dt: float) -> np.ndarray:
    """The scope's sample times: a trigger 40% into the record, off the printed grid."""
    return dt * (np.arange(POINTS) - 0.4 * POINTS + 0.37)


def _four_digits(t: float) -> str:
    return f"{t:.3e}"


@pytest.mark.parametrize("decade", DECADES)
def test_a_four_digit_time_column_reads_on_the_headers_time_base_at_every_decade(tmp_path, decade):
    dt = 3.2 * 10.0 ** decade
    printed = [_four_digits(t) for t in _grid(dt)]
    rounding = np.max(np.abs(np.array(printed, dtype=float) - (float(printed[0]) + dt * np.arange(POINTS))))
    assert rounding > TIME_TOLERANCE * dt  # the printing alone is past the old bound of 0.1 of a sample
    path = tmp_path / "TEK0000.CSV"
    _tbs1000c(path, dt, printed)
    (w,) = read_waveforms(path)
    assert w.preamble.x_increment == float(f"{dt:g}")
    np.testing.assert_allclose(w.time(), float(printed[0]) + w.preamble.x_increment * np.arange(POINTS),
                               rtol=0, atol=1e-9 * dt)


@pytest.mark.parametrize("decade", DECADES)
def test_a_time_past_what_the_printed_digits_allow_is_refused_and_one_within_is_not(tmp_path, decade):
    dt = float(f"{3.2 * 10.0 ** decade:g}")
    printed = [_four_digits(t) for t in _grid(dt)]
    x0 = float(printed[0])
    j = POINTS - 1  # the last time: the furthest from the first, moved later (the column still increases)
    q, q0 = printed_quantum(printed[j]), printed_quantum(printed[0])
    on_grid = x0 + dt * j
    bound = TIME_TOLERANCE * dt + q / 2 + q0 / 2  # the reader's bound there (csv_columns.time_base)
    # one unit of the last digit at a time: the furthest within the bound, then the nearest past it
    within = on_grid + q * math.floor((bound - q / 2) / q)
    past = on_grid + q * (math.floor(bound / q) + 2)
    for shifted, reads in ((within, True), (past, False)):
        cells = list(printed)
        cells[j] = _four_digits(shifted)
        assert abs(float(cells[j]) - on_grid) <= bound if reads else abs(float(cells[j]) - on_grid) > bound
        path = tmp_path / f"shifted_{reads}.csv"
        _tbs1000c(path, dt, cells)
        if reads:
            read_waveforms(path)
        else:
            with pytest.raises(InstrumentError, match="beyond the rounding of the digits printed"):
                read_waveforms(path)


@pytest.mark.parametrize("cell,quantum", [
    ("6.109e-05", 1e-8), ("-8.000e-01", 1e-4), ("0.0008", 1e-4), ("1.00E-09", 1e-11),
    ("24999.16015625", 1e-8), ("2000", 1.0), ("4e-08", 1e-8), ("-2.5000000000E-04", 1e-14)])
def test_the_unit_in_the_last_printed_digit(cell, quantum):
    assert printed_quantum(cell) == pytest.approx(quantum, rel=1e-12)


@pytest.mark.parametrize("column,quanta", [
    (["-8.000e-01", "0.000e+00", "6.109e-05"], [1e-4, 0.0, 1e-8]),  # a fixed form: every cell its digits
    (["-0.00000033", "-0.000000329", "0.00000067", "0.0000033"], [1e-9, 1e-9, 1e-9, 1e-8]),  # TDS2001C
    (["0", "1e-06", "2e-06", "1.5e-06"], [0.0, 1e-7, 1e-7, 1e-7]),  # shortest form: 1.5e-06 shows two digits
    (["-880.000006873E-6", "-1.0000091E-6"], [1e-15, 1e-17]),  # engineering form, twelve digits
])
def test_a_columns_rounding_comes_from_its_most_digits(column, quanta):
    np.testing.assert_allclose(printed_quanta(column), quanta, rtol=1e-12, atol=0)


def test_a_zero_index_printed_coarser_than_a_sample_leaves_the_time_base_to_the_column(tmp_path):
    """'Zero Index,2.5e+04' is 25000 to within 500 samples as printed: the time base is then
    the TIME column's (whose cells are exact here), not a start 500 samples loose."""
    dt = 4e-8
    times = [f"{(k - 24999.4) * dt:.8e}" for k in range(POINTS)]
    path = tmp_path / "coarse_zero.csv"
    path.write_text("\n".join(["Model,MSO54", "Waveform Type,ANALOG", "Zero Index,2.5e+04", "Sample Interval,4e-08",
                               f"Record Length,{POINTS}", "Horizontal Units,s", "TIME,CH1"]
                              + [f"{t},0.01" for t in times]) + "\n")
    (w,) = read_waveforms(path)
    assert w.preamble.x_zero == float(times[0])


@pytest.mark.parametrize("cell", ["", ".", "  ", "e5", "+"])
def test_a_cell_with_no_digit_prints_no_rounding(cell):
    assert printed_quantum(cell) == 0.0


@pytest.mark.parametrize("rows,reads", [(5000, True), (5011, True), (4989, True), (5013, False), (2983, False)])
def test_a_gated_records_rows_are_held_to_its_printed_gate(tmp_path, rows, reads):
    """Gating 25.0% to 75.0% of 10000 points: 5000 rows, give or take the rounding of the
    two printed percentages (0.05% of 10000 each) and a row; a file cut short is refused."""
    path = tmp_path / "gated.csv"
    path.write_text("\n".join(["Model,MSO54", "Sample Interval,1e-06", "Record Length,10000",
                               "Gating,25.0% to 75.0%", "Horizontal Units,s", "TIME,CH1"]
                              + [f"{k * 1e-6:.8e},0.01" for k in range(rows)]) + "\n")
    if reads:
        (w,) = read_waveforms(path)
        assert w.preamble.points == rows
    else:
        with pytest.raises(InstrumentError, match="Record Length says 10000 points gated 25.0% to 75.0%"):
            read_waveforms(path)


@pytest.mark.parametrize("with_interval", [True, False])
def test_stamps_that_the_printing_repeats_read_on_the_records_time_base(tmp_path, with_interval):
    """Past 1e-4 s, four digits step by 1e-7 s, three samples of 3.2e-8 s: the column
    repeats stamps (1.000e-04 after 1.000e-04). Such a file had been refused as a column
    that "does not increase"; without a Sample Interval its step is the column's span over
    its samples (the first rounded step, 3.0e-8 s, had been taken and the file refused)."""
    dt = 3.2e-8
    times = [f"{6.1e-5 + k * dt:.3e}" for k in range(POINTS)]
    assert len(set(times)) < POINTS  # stamps repeat
    rows = ["Model,TBS1102C", "Horizontal Units,S", *(["Sample Interval,3.2e-08"] if with_interval else []),
            f"Record Length,{POINTS}", "Vertical Units,V", "TIME,CH1"]
    path = tmp_path / "repeats.csv"
    path.write_text("\n".join(rows + [f"{t},0.01" for t in times]) + "\n")
    (w,) = read_waveforms(path)
    assert w.preamble.x_increment == pytest.approx(dt, rel=1e-3 if not with_interval else 1e-15)
    assert w.preamble.x_zero == pytest.approx(6.1e-5, abs=1e-12)
