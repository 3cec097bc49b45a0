"""A full disk under every command that writes: one line naming the path and the cause,
exit 2, no traceback, nothing truncated or empty left behind, and the same command run
again once there is room succeeds.

The disk is made full by a file-size limit on the command's process (RLIMIT_FSIZE, DISK_FULL),
which makes every write past the limit fail with EFBIG ("File too large") as ENOSPC would.
Each limit is below the size of what the command writes, so the failure comes from a real
write in the middle of it. A failed run leaves nothing new but whole files: no folder it
created empty, no 0-byte file, no lock file. Only the failing run needs a process of its
own (the limit, its exit status, its stderr); the runs with room (a fit that fills its
cache first, the run again) are rig.cli.main in this process, its exit status and stderr
checked the same way (an exception it lets out fails the test, as a traceback would). The
fit that fills the cache runs once for the file (``fitted``); the cases that start from it
start from a copy of its folder."""
from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np
import pytest
from test_bad_inputs import VEL, S, one_line

from instruments.archive import Archive
from instruments.formats.isf import read_isf
from rig.cli import main

LAYOUT1 = Path(__file__).parents[1] / "instruments" / "data" / "layout1.h5"
POINTS = "F_d [N],F_d_sd [N],V_s [m/s],V_s_sd [m/s]\n0.5,0.05,130,4\n0.9,0.09,150,4.5\n1.6,0.16,175,5\n"
FIT = ["fit", "ptfe20_gravity", "--points", "{d}/points.csv", "--param", "chain.youngs_modulus=0.5 GPa:3 GPa",
       "--out", "{d}/fit", "--quiet"]
SMALL = ["--set", "chain.beads=20", "--set", "gauges.upper.bead=6", "--set", "gauges.lower.bead=12",
         "--set", "solver.duration=0.5 ms", "--set", "scope.record_length=2000"]

CASES = {
    "shot --export": (1000, ["shot", S, "--seed", "1", "--export", "{d}/shots"]),
    "shot --export csv, a new folder": (1000, ["shot", S, "--seed", "1", "--export", "{d}/new/exp", "--format",
                                              "csv"]),
    "shot --out": (20000, ["shot", S, "--seed", "1", "--out", "{d}/a.h5"]),
    "sweep --out": (20000, ["sweep", S, "--vary", "striker.velocity=0.6:0.9:2", "--out", "{d}/s.h5", "--quiet"]),
    "mc --out": (3000, ["mc", S, "--shots", "8", "--batch", "4", "--vary", VEL, "--out", "{d}/study", "--quiet"]),
    "mc --out, two workers": (3000, ["mc", S, "--shots", "8", "--batch", "4", "--vary", VEL, "--out", "{d}/study",
                                     "--quiet", "--workers", "2"]),
    "mc --traces": (3000, ["mc", S, "--shots", "8", "--batch", "4", "--vary", VEL, "--traces", "--out",
                           "{d}/study", "--quiet"]),
    "mc --out, the report": (20000, ["mc", S, "--shots", "8", "--batch", "4", "--vary", VEL, "--out", "{d}/study",
                                     "--quiet"]),
    "import": (5000, ["import", "{realdata}/tek_16bit_dpo.isf", "--into", "{d}/a.h5"]),
    "upgrade": (LAYOUT1.stat().st_size + 2000, ["upgrade", "{d}/old.h5"]),
    "fit, the cache": (300, FIT),
    "fit, the report": (8000, FIT),
    # 24 steps (a 154 kB chain): by then (not by 20) walkers have had moves refused and met a candidate
    # whose figure is refused (its pulse never falls to 1%), as they did in 40
    "fit --posterior, the chain": (3000, [*FIT, "--posterior", "24", "--walkers", "4"]),
    # the tables and results.json (18 kB) fit, each figure (48 to 140 kB; the first drawn 84 kB) does not:
    # the failed run leaves the study's numbers whole (tests/cli/test_full_disk_studies.py)
    "reproduce --out": (40000, ["reproduce", "daraio2006", "--out", "{d}/r", "--quiet", "--json"]),
    # two frames (the fewest): a movie written whole or not at all; more frames only render longer
    "animate --out": (2000, ["animate", S, *SMALL, "--frames", "2", "--out", "{d}/a.gif", "--quiet"]),
}


# a rig command in a process whose files cannot grow past argv[1] bytes (SIGXFSZ ignored: the
# write fails with EFBIG instead of the signal ending the process)
DISK_FULL = """
import resource, signal, sys
signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
# no .pyc written past the limit: the import system writes one in a single write(), and a short write
# under the limit is renamed into place, a truncated .pyc for every later process ("marshal data too short")
sys.dont_write_bytecode = True
limit = int(sys.argv[1])
resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))
from rig.cli import main
sys.exit(main(sys.argv[2:]))
"""


def expand(argv, d: Path, realdata) -> list:
    return [a.replace("{d}", str(d)).replace("{realdata}", str(realdata)) for a in argv]


def run_case(argv, d: Path, realdata, limit=None):
    """``argv`` in a process of its own in folder ``d``, its files limited to ``limit``
    bytes (DISK_FULL) where one is given."""
    code = DISK_FULL if limit else "import sys\nfrom rig.cli import main\nsys.exit(main(sys.argv[2:]))\n"
    # and none by the processes it starts (rig mc --workers: spawned interpreters, the limit inherited); under
    # coverage (docs/how-to/contributing.md) such a process is not measured: it could not save coverage's data,
    # and coverage's complaint would be a second line on its stderr
    env = dict({k: v for k, v in os.environ.items() if not k.startswith("COVERAGE_")},
               PYTHONDONTWRITEBYTECODE="1") if limit else None
    return subprocess.run([sys.executable, "-c", code, str(limit or 0), *expand(argv, d, realdata)], check=False,
                          capture_output=True, text=True, cwd=d, timeout=600, env=env)


def run_here(argv, d: Path, realdata, monkeypatch, capsys) -> tuple:
    """``argv`` by rig.cli.main in this process, in folder ``d`` (a run with room):
    (exit status, stderr, stdout)."""
    capsys.readouterr()
    with monkeypatch.context() as m:
        m.chdir(d)
        try:
            code = main(expand(argv, d, realdata))
        except SystemExit as exc:
            code = exc.code
    out, err = capsys.readouterr()
    return code, err, out


def target(argv) -> str:
    """The path ``argv`` writes: its --out, --export or --into, else (upgrade) its file."""
    flag = next((f for f in ("--out", "--export", "--into") if f in argv), None)
    return argv[argv.index(flag) + 1] if flag else argv[1]


def whole(path: Path):
    """Fail unless ``path`` is a whole file of its kind (what a reader of it needs)."""
    kind = path.suffix.lower()
    assert path.stat().st_size > 0, f"{path}: empty"
    if kind == ".h5":
        with h5py.File(path, "r") as f:
            archive = f.attrs.get("creator") == "sonic-rig" and f.attrs.get("layout_version") in (2, 3)
        if archive:
            assert Archive(path).verify()["bad"] == [], path
    elif kind == ".isf":
        assert read_isf(path)
    elif kind == ".json":
        json.loads(path.read_text())
    elif kind == ".npz":
        with np.load(path) as z:
            [z[n] for n in z.files]
    elif kind in (".png", ".gif"):
        from PIL import Image

        with Image.open(path) as im:
            im.load()
    else:
        path.read_text()


def check_left(d: Path, before: set | None = None):
    """Every file under ``d`` whole; after a failed run (``before``: the paths there before
    it), nothing new but whole files: no lock file, no empty folder."""
    for p in d.rglob("*"):
        if p.is_file():
            assert ".tmp" not in p.name, f"{p}: a temporary file left behind"
            if p.suffix != ".lock":  # a lock file holds no data
                whole(p)
    for p in set(d.rglob("*")) - (before if before is not None else set(d.rglob("*"))):
        assert p.suffix != ".lock", f"{p}: a lock file left behind by a failed run"
        assert not (p.is_dir() and not any(p.iterdir())), f"{p}: an empty folder left behind by a failed run"


# the cases tests/cli/test_full_disk_studies.py runs (the longest: so the suite's workers share them)
STUDIES = ("reproduce --out", "mc --out, two workers", "mc --traces", "mc --out")


@pytest.fixture(scope="module")
def fitted(tmp_path_factory):
    """A folder with points.csv and FIT's folder, its evaluations cached: run once, each
    case that starts from a filled cache starts from a copy of it."""
    d = tmp_path_factory.mktemp("fitted")
    (d / "points.csv").write_text(POINTS)
    with pytest.MonkeyPatch.context() as m:
        m.chdir(d)
        assert main(expand(FIT, d, None)) in (0, 1)
    return d


@pytest.mark.parametrize("case", [c for c in CASES if c not in STUDIES])
def test_a_full_disk_is_one_line_leaves_nothing_broken_and_a_second_run_succeeds(tmp_path, realdata, case,
                                                                                    monkeypatch, capsys, request):
    check_full_disk(tmp_path, realdata, case, monkeypatch, capsys, request)


def check_full_disk(tmp_path: Path, realdata, case: str, monkeypatch, capsys, request=None):
    """Case ``case`` of CASES under its file-size limit (fill_disk), then run again with
    room (run_again)."""
    argv = fill_disk(tmp_path, realdata, case, request)
    run_again(argv, tmp_path, realdata, monkeypatch, capsys)


def fill_disk(tmp_path: Path, realdata, case: str, request=None) -> list:
    """Case ``case`` of CASES under its file-size limit: one line naming the path it was
    told to write and the cause, exit 2, nothing broken left; returns its argv. A fit case
    other than the cache's starts from the module's ``fitted`` folder (``request``: the
    test's, to get it)."""
    limit, argv = CASES[case]
    if argv[0] == "animate":
        pytest.importorskip("pyvista")
    if argv[0] == "upgrade":
        shutil.copyfile(LAYOUT1, tmp_path / "old.h5")
    if argv[0] == "fit":
        if case == "fit, the cache":
            (tmp_path / "points.csv").write_text(POINTS)
        else:  # the cache filled by a first run: this one writes the scene and report first
            shutil.copytree(request.getfixturevalue("fitted"), tmp_path, dirs_exist_ok=True)
    before = {p: p.read_bytes() for p in tmp_path.rglob("*") if p.is_file() and p.suffix != ".lock"}
    there = set(tmp_path.rglob("*"))
    r = run_case(argv, tmp_path, realdata, limit)
    assert r.returncode == 2, r.stderr
    line = one_line(r.stderr)
    written = expand([target(argv)], tmp_path, realdata)[0]
    assert line.startswith(f"rig {argv[0]}: error: {written}") and line.endswith(": File too large"), line
    check_left(tmp_path, there)
    if argv[0] == "mc" and (tmp_path / "study" / "study.json").exists():  # whole: the study can resume
        assert json.loads((tmp_path / "study" / "study.json").read_text())["shots"] == 8
    if argv[0] == "shot" and "--export" in argv:  # several files: all of them or none, and no new empty folder
        assert not list(tmp_path.rglob("*.isf")) and not list(tmp_path.rglob("*.csv"))
    for p in (p for p in before if p.suffix == ".h5"):
        assert p.read_bytes() == before[p], f"{p}: changed by a failed write"
    return argv


def run_again(argv, d: Path, realdata, monkeypatch, capsys) -> str:
    """``argv`` run again in folder ``d`` once there is room (in this process): it
    succeeds, says nothing of a traceback, and leaves every file whole; its stdout."""
    code, err, out = run_here(argv, d, realdata, monkeypatch, capsys)
    assert code in ((0, 1) if argv[0] == "fit" else (0,)), err
    assert "Traceback" not in err
    check_left(d)
    return out
