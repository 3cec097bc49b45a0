"""What a fit is fitted to.

Points: a table of measured (F_d, V_s) with their standard uncertainties, like Table 1 of
Daraio et al. 2006. A CSV file whose header names each column with its unit in brackets:

    F_d [N], F_d_sd [N], V_s [m/s], V_s_sd [m/s], magnet.force [N]

Any other column named by a numeric scene key sets that key for its row (the rows of one
set of such values are one configuration: one speed-amplitude curve of the model).

Traces: scope records of shots (ISF/CSV files of one shot's channels, or the shots of an
archive), each channel compared, sample by sample, with the model's record of the same
channel (rig.fit.traces).
"""
from __future__ import annotations

import csv
import math
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from rig.errors import RigError, invalid
from rig.experiment.scene import schema_node
from rig.units import check_digits, is_number, quantity

POINT_COLUMNS = {"F_d": "N", "F_d_sd": "N", "V_s": "m/s", "V_s_sd": "m/s"}
_HEADER = re.compile(r"^\s*([A-Za-z_][\w.]*)\s*(?:\[(.+)\])?\s*$")


@dataclass(frozen=True)
class Points:
    """Measured points: force F_d (N), speed V_s (m/s), their standard uncertainties, and
    each row's configuration (a tuple of scene overrides, "key=SI value")."""

    force: np.ndarray
    force_sd: np.ndarray
    speed: np.ndarray
    speed_sd: np.ndarray
    configs: tuple
    source: str

    @property
    def n(self) -> int:
        return self.force.size

    def configurations(self) -> list:
        """The distinct configurations, in first-seen order."""
        return list(dict.fromkeys(self.configs))

    def subset(self, rows) -> Points:
        rows = np.asarray(rows)
        return Points(self.force[rows], self.force_sd[rows], self.speed[rows], self.speed_sd[rows],
                      tuple(self.configs[i] for i in rows), self.source)


def read_points(path) -> Points:
    """Points from a CSV file (module doc). Raises RigError naming the file, row and column."""
    path = Path(path)
    try:
        text = path.read_text()
    except (OSError, UnicodeDecodeError) as exc:
        raise RigError(f"--points {path}: cannot read ({exc})") from None
    numbered = [(n, r) for n, r in enumerate(csv.reader(text.splitlines()), start=1)
                if r and not r[0].lstrip().startswith("#")]
    lines, rows = [n for n, _ in numbered], [r for _, r in numbered]  # the file's line of each row
    if len(rows) < 2:
        raise RigError(f"--points {path}: no data (a header and at least one row are needed)")
    columns = []
    for head in rows[0]:
        m = _HEADER.match(head)
        if not m:
            raise invalid(f"--points {path} header", head, "NAME [unit], e.g. 'F_d [N]'")
        name, unit = m.group(1), m.group(2)
        if name in POINT_COLUMNS:
            si = POINT_COLUMNS[name]
        else:
            try:
                spec = schema_node(name)
            except KeyError:
                raise invalid(f"--points {path} header", name,
                              f"one of {', '.join(POINT_COLUMNS)} or a numeric scene key") from None
            si = "1" if spec is float else spec
            if not isinstance(si, str):
                raise invalid(f"--points {path} header", name, "a numeric scene key")
        if si != "1" and not unit:
            raise invalid(f"--points {path} header", head, f"needs its unit, e.g. '{name} [{si}]'")
        columns.append((name, unit, si))
    names = [c[0] for c in columns]
    missing = [c for c in POINT_COLUMNS if c not in names]
    if missing:
        raise invalid(f"--points {path}", ", ".join(names), f"columns missing: {', '.join(missing)}")
    data: dict[str, list[float]] = {n: [] for n in names}
    for i, row in zip(lines[1:], rows[1:]):
        if len(row) != len(columns):
            raise invalid(f"--points {path} line {i}", ",".join(row), f"{len(columns)} values")
        for (name, unit, si), cell in zip(columns, row):
            check_digits(cell, f"--points {path} line {i} {name}")
            try:
                if not is_number(cell):
                    raise RigError(cell)
                x = float(cell) if si == "1" else quantity(f"{cell.strip()} {unit}", si, name)
            except RigError:
                raise invalid(f"--points {path} line {i} {name}", cell, f"a number in {unit or 'no unit'}") from None
            if not math.isfinite(x):
                raise invalid(f"--points {path} line {i} {name}", cell, "a finite number")
            data[name].append(x)
    arr = {n: np.array(v) for n, v in data.items()}
    for name in POINT_COLUMNS:
        if np.any(arr[name] <= 0):
            j = int(np.flatnonzero(arr[name] <= 0)[0])
            raise invalid(f"--points {path} line {lines[j + 1]} {name}", float(arr[name][j]),
                          "> 0 (forces, speeds and uncertainties)")
    first: dict[tuple, int] = {}
    for j, values in enumerate(zip(*(arr[n] for n in names))):
        if values in first:
            raise invalid(f"--points {path} line {lines[j + 1]}", ",".join(rows[j + 1]),
                          f"repeats line {first[values]}: the same point counted twice would narrow the intervals")
        first[values] = lines[j + 1]
    keys = [n for n in names if n not in POINT_COLUMNS]
    configs = tuple(tuple(f"{k}={float(arr[k][j])!r}" for k in keys) for j in range(len(rows) - 1))
    return Points(arr["F_d"], arr["F_d_sd"], arr["V_s"], arr["V_s_sd"], configs, str(path))
