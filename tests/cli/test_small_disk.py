"""A real full disk and a read-only one under the commands that write: a tmpfs of a few
kB that fills in the middle of the command's writes (ENOSPC, where tests/cli/test_full_disk.py
uses a file-size limit), then made larger, and one remounted read-only. The same checks:
one line naming the path and the cause, exit 2, nothing broken left, and the command
succeeds once there is room. (Kept apart from test_full_disk.py so the suite's workers
share these runs.)"""
from __future__ import annotations

import subprocess

import pytest
from test_bad_inputs import one_line
from test_full_disk import CASES, POINTS, check_left, expand, run_again, run_case, target


@pytest.fixture
def small_disk(tmp_path, request):
    """A real file system of ``request.param`` (tmpfs, "16k"): writes past it fail with ENOSPC."""
    disk = tmp_path / "disk"
    disk.mkdir()
    r = subprocess.run(["mount", "-t", "tmpfs", "-o", f"size={request.param}", "tmpfs", str(disk)],
                       check=False, capture_output=True, text=True)
    if r.returncode:
        pytest.skip(f"cannot mount a tmpfs here ({r.stderr.strip() or 'mount failed'}): the file-size-limit cases "
                    "above cover the same writes")
    yield disk
    subprocess.run(["umount", "-l", str(disk)], check=False, capture_output=True)


@pytest.mark.parametrize("case,small_disk", [("shot --export", "16k"), ("shot --export csv, a new folder", "16k"),
                                             ("shot --out", "64k"), ("mc --out", "64k"), ("mc --traces", "64k"),
                                             ("import", "16k"), ("fit, the cache", "16k")], indirect=["small_disk"])
def test_a_real_full_disk_is_one_line_and_the_command_succeeds_once_there_is_room(small_disk, realdata, case,
                                                                                  monkeypatch, capsys):
    _, argv = CASES[case]
    if argv[0] == "fit":
        (small_disk / "points.csv").write_text(POINTS)
    there = set(small_disk.rglob("*"))
    r = run_case(argv, small_disk, realdata)
    assert r.returncode == 2, r.stderr
    line = one_line(r.stderr)
    written = expand([target(argv)], small_disk, realdata)[0]
    assert line.startswith(f"rig {argv[0]}: error: {written}") and line.endswith(": No space left on device"), line
    check_left(small_disk, there)
    subprocess.run(["mount", "-o", "remount,size=64m", str(small_disk)], check=True)  # room made
    run_again(argv, small_disk, realdata, monkeypatch, capsys)  # in this process: the disk is real


@pytest.mark.parametrize("case,small_disk", [("shot --export", "1m"), ("mc --out", "1m"), ("shot --out", "1m")],
                         indirect=["small_disk"])
def test_a_read_only_disk_is_one_line(small_disk, realdata, case):
    _, argv = CASES[case]
    (small_disk / "study").mkdir()  # a folder that exists, on a disk that takes no write
    subprocess.run(["mount", "-o", "remount,ro", str(small_disk)], check=True)
    r = run_case(argv, small_disk, realdata)
    assert r.returncode == 2, r.stderr
    line = one_line(r.stderr)
    assert line.startswith(f"rig {argv[0]}: error: {small_disk}") and "Read-only file system" in line, line
