"""The bad-input corpus: every user mistake and I/O failure on the command line ends in
exactly one line on stderr naming the field or path, exit 2, never a traceback.

Each case is (argv, needle): ``{d}`` in an argument is the case's scratch folder (holding
the files of ``_files``); the one error line must contain ``needle``. A full disk under
each command that writes: tests/cli/test_full_disk.py."""
from __future__ import annotations

import os
import subprocess
import sys

import pytest

from rig.cli import main

S = "ptfe52_magnetic"
VEL = "striker.velocity=normal(0.89 m/s, 0.01 m/s)"


def _files(d):
    """The scratch files the cases name."""
    (d / "binary.toml").write_bytes(bytes(range(256)) * 4)
    (d / "empty.toml").write_text("")
    (d / "cut.toml").write_text('[chain]\nmaterial = "ptfe"\ndiameter = "4.76 m')
    (d / "existing.txt").write_text("already here\n")
    (d / "folder").mkdir()
    (d / "empty.isf").write_bytes(b"")
    (d / "junk.isf").write_bytes(b"\x00\x01garbage" * 50)
    (d / "empty.csv").write_text("")
    (d / "text.h5").write_text("not an archive\n")
    (d / "sub").mkdir()
    (d / "sub" / "plainfile").write_text("x")


def _set(*items):
    out = []
    for item in items:
        out += ["--set", item]
    return out


CASES = [
    # the elastic-plastic law and the magnet's hold
    (["shot", S, *_set("chain.contact_law=thornton", "chain.yield_force=-1 N")], "chain.yield_force"),
    (["shot", "ptfe52_gravity", *_set("chain.contact_law=thornton", "chain.yield_force=1 N", "magnet.force=0 N",
                                      "magnet.hold=60 s")], "magnet.hold"),
    (["shot", S, *_set("chain.yield_force=1 N")], "chain.yield_force"),  # another law's key
    (["reproduce", "daraio2006", "--fitted", "--family", "no such family", "--out", "{d}/r"], "--family"),
    (["reproduce", "daraio2006", "--family", "hertz", "--out", "{d}/r"], "--family"),
    # shot: scenes and files
    (["shot", "no_such_scene"], "no_such_scene"),
    (["shot", "{d}/missing.toml"], "missing.toml"),
    (["shot", "{d}/folder"], "folder"),
    (["shot", "{d}/binary.toml"], "binary.toml"),
    (["shot", "{d}/empty.toml"], "chain"),
    (["shot", "{d}/cut.toml"], "cut.toml"),
    # shot: keys, values, units, ranges
    (["shot", S, *_set("striker.velocity=-1")], "striker.velocity"),
    (["shot", S, *_set("striker.velocity=nan")], "striker.velocity"),
    (["shot", S, *_set("striker.velocity=inf")], "striker.velocity"),
    (["shot", S, *_set("striker.velocity=1 kg")], "striker.velocity"),
    # far outside the contact law: the solver's refusal names the key, the overlap and a safe speed
    (["shot", S, *_set("striker.velocity=1e9")], "striker.velocity = 1e+09 m/s with striker.mass = 0.00047 kg "
                                                  "could press the striker 81.6 m into the top bead"),
    (["shot", S, *_set("striker.velocity=120")], "striker.velocity = 120 m/s"),
    (["shot", S, *_set("gauges.lower.bead=20")], "gauges.lower and gauges.upper are both on bead 20 (from the top)"),
    (["shot", S, *_set("magnet.force=1e4")], "the static load, 1e+04 N at contact 52 (magnet.force and the chain's "
                                              "weight), presses it 1.6 times a bead's 2.38 mm radius together"),
    # a striker longer than the tube: its mass and the tube's length are both named
    (["shot", S, *_set("striker.mass=1e6")], "striker.mass = 1e+06 kg and holder.length = 0.4 m: a 4.76 mm "
                                              "alumina striker of that mass is 1.441e+07 m long, longer than the tube"),
    (["shot", S, *_set("holder.length=1 mm")], "striker.mass = 0.00047 kg and holder.length = 0.001 m"),
    (["shot", S, *_set("chain.colour=red")], "chain.colour"),
    (["shot", S, *_set("chain.beads=0")], "chain.beads"),
    (["shot", S, *_set("chain.beads=-5")], "chain.beads"),
    (["shot", S, *_set("chain.beads=2.5")], "chain.beads"),
    (["shot", S, *_set("chain.material=wood")], "wood"),
    (["shot", S, *_set("chain.diameter=0")], "diameter"),
    (["shot", S, *_set("chain.magnetic_bead=maybe")], "chain.magnetic_bead"),
    (["shot", S, *_set("solver.method=euler")], "euler"),
    (["shot", S, *_set("solver.accuracy=0")], "accuracy"),
    (["shot", S, *_set("solver.accuracy=nan")], "accuracy"),
    (["shot", S, *_set("solver.duration=0")], "solver.duration"),
    (["shot", S, *_set("solver.duration=-2 ms")], "solver.duration"),
    (["shot", S, *_set("solver.accuracy=5")], "solver.accuracy = 5.0: relative accuracy target in [1e-10, 0.1]"),
    (["shot", S, *_set("scope.channels.CH1.volts_per_div=0")],
     "scope.channels.CH1.volts_per_div = 0.0: allowed 0.000999 <= volts_per_div <= 10.01 (V/div)"),
    (["shot", S, *_set("solver.duration=1000 s")], "--allow-large"),
    (["shot", S, *_set("solver.sample_interval=0")], "sample_interval"),
    (["shot", S, *_set("scope.sample_interval=-1")], "scope.sample_interval"),
    (["shot", S, *_set("scope.record_length=0")], "record_length"),
    (["shot", S, *_set("scope.trigger.source=CH9")], "CH9"),
    (["shot", S, *_set("scope.trigger.slope=sideways")], "slope"),
    (["shot", S, *_set("scope.trigger.pre_trigger=2")], "pre_trigger"),
    (["shot", S, *_set("scope.channels.CH1.volts_per_div=0")], "volts_per_div"),
    (["shot", S, *_set("gauges.upper.bead=500")], "gauges.upper.bead"),
    (["shot", S, *_set("gauges.upper.channel=CH7")], "CH7"),
    (["shot", S, *_set("magnet.force=-1")], "magnet.force"),
    (["shot", S, *_set("noequals")], "--set"),
    (["shot", S, *_set("chain.beads=100000", "gauges.lower.bead=99990")], "holder.length"),
    (["shot", S, *_set("chain.beads=100000", "gauges.lower.bead=99990", "holder.length=1000",
                       "solver.duration=500 ms")], "--allow-large"),
    (["shot", S, "--seed", "-1"], "--seed"),
    (["shot", S, "--seed", "abc"], "--seed"),
    (["shot", S, "--seed", str(2**64)], "--seed"),
    (["shot", S, "--format", "xyz"], "--format"),
    (["shot", S, "--export", "{d}/existing.txt", "--seed", "1"], "existing.txt"),
    (["shot", S, "--out", "{d}/sub/plainfile/a.h5", "--seed", "1"], "plainfile"),
    (["shot", S, "--out", "{d}/folder", "--seed", "1"], "folder"),
    # sweep
    (["sweep", S, "--vary", "striker.velocity"], "--vary"),
    (["sweep", S, "--vary", "striker.velocity=0.5:1"], "--vary"),
    (["sweep", S, "--vary", "striker.velocity=0.3:1.5:0"], "COUNT"),
    (["sweep", S, "--vary", "striker.velocity=1.5:0.3:3"], "START"),
    (["sweep", S, "--vary", "chain.colour=1:2:3"], "chain.colour"),
    (["sweep", S, "--vary", "striker.velocity=nan:1:3"], "striker.velocity"),
    (["sweep", S, "--vary", "striker.velocity=-1:1:3"], "striker.velocity"),
    (["sweep", S, "--vary", "striker.velocity=0.3:1.5:100000000"], "--allow-large"),
    (["sweep", S, "--vary", "striker.velocity=0.3:1.5:3", *_set("chain.beads=1.5")], "chain.beads"),
    # mc
    (["mc", S, "--shots", "0", "--vary", VEL, "--out", "{d}/mc"], "--shots"),
    (["mc", S, "--shots", "8", "--vary", "chain.beads=uniform(10, 60)", "--out", "{d}/mc"],
     "--vary = 'chain.beads': a whole-number key (a count or an index) cannot take a continuous distribution"),
    (["mc", S, "--shots", "-5", "--vary", VEL, "--out", "{d}/mc"], "--shots"),
    (["mc", S, "--shots", "8", "--batch", "0", "--vary", VEL, "--out", "{d}/mc"], "--batch"),
    (["mc", S, "--shots", "100000000", "--vary", VEL, "--out", "{d}/mc"], "add --allow-large to run it anyway"),
    (["mc", S, "--shots", "8", "--workers", "0", "--vary", VEL, "--out", "{d}/mc"], "--workers"),
    (["mc", S, "--shots", "8", "--accuracy", "0", "--vary", VEL, "--out", "{d}/mc"], "accuracy"),
    (["mc", S, "--shots", "8", "--out", "{d}/mc"], "--vary"),
    (["mc", S, "--shots", "8", "--vary", "striker.velocity=normal(0.89 m/s)", "--out", "{d}/mc"], "normal"),
    (["mc", S, "--shots", "8", "--vary", "striker.velocity=normal(0.89 m/s, -1 m/s)", "--out", "{d}/mc"],
     "striker.velocity"),
    (["mc", S, "--shots", "8", "--vary", "gauges.nosuch.gain=lognormal(0, 0.1)", "--out", "{d}/mc"], "nosuch"),
    (["mc", S, "--shots", "8", "--vary", "chain.colour=normal(1, 1)", "--out", "{d}/mc"], "chain.colour"),
    (["mc", S, "--shots", "8", "--vary", "striker.velocity=uniform(1 kg, 2 kg)", "--out", "{d}/mc"],
     "striker.velocity"),
    (["mc", S, "--shots", "8", "--vary", VEL, *_set("striker.velocity=-1"), "--out", "{d}/mc"], "striker.velocity"),
    (["mc", S, "--shots", "8", "--vary", VEL, *_set("solver.duration=1000 s"), "--out", "{d}/mc"],
     "--allow-large"),
    (["mc", S, "--shots", "8", "--vary", VEL, "--out", "{d}/existing.txt"], "existing.txt"),
    (["mc", S, "--shots", "8", "--vary", VEL, "--max-failed", "200%", "--out", "{d}/mc"], "--max-failed"),
    (["mc", S, "--shots", "8", "--vary", VEL, "--max-failed", "x", "--out", "{d}/mc"], "--max-failed"),
    (["mc", S, "--shots", "8", "--vary", VEL, "--worker-timeout", "0", "--out", "{d}/mc"], "--worker-timeout"),
    (["mc", S, "--shots", "abc", "--vary", VEL, "--out", "{d}/mc"], "--shots"),
    # animate
    (["animate", S, "--out", "{d}/movie.avi"], "movie.avi"),
    (["animate", S, "--out", "{d}/m.gif", "--frames", "0"], "--frames"),
    (["animate", S, "--out", "{d}/m.gif", "--frames", "-3"], "--frames"),
    (["animate", S, "--out", "{d}/m.gif", "--exaggerate", "nan"], "--exaggerate"),
    (["animate", S, "--out", "{d}/m.gif", *_set("solver.duration=1000 s")], "--allow-large"),
    # reproduce
    (["reproduce", "nosuch", "--out", "{d}/r"], "nosuch"),
    (["reproduce", "daraio2006", "--out", "{d}/existing.txt"], "existing.txt"),
    (["reproduce", "daraio2006", "--sensitivity", "--out", "{d}/r", *_set("chain.nosuch=3")], "chain.nosuch"),
    (["reproduce", "daraio2006", "--identifiability", "--out", "{d}/r", "--param", "chain.yield_force=2 N:0.3 N",
      "--truth", "0.8 N"], "LO < HI"),
    (["reproduce", "daraio2006", "--identifiability", "--out", "{d}/r", "--param", "chain.yield_force=0.3 N:2 N",
      "--truth", "3 N"], "chain.yield_force truth"),
    (["reproduce", "daraio2006", "--identifiability", "--out", "{d}/r", "--param", "chain.nosuch=0.3 N:2 N",
      "--truth", "1 N"], "chain.nosuch"),
    (["reproduce", "daraio2006", "--identifiability", "--out", "{d}/r", "--param", "chain.yield_force=0.3 N:2 N"],
     "--truth"),
    (["reproduce", "daraio2006", "--out", "{d}/r", *_set("chain.yield_force=1 N")], "--identifiability"),
    # theory
    (["theory", "--material", "wood", "--f0", "1"], "wood"),
    (["theory", "--f0", "-1"], "--f0"),
    (["theory", "--f0", "nan"], "--f0"),
    (["theory", "--f0", "inf"], "--f0"),
    (["theory", "--f0", "1", "--diameter", "4.76 kg"], "--diameter"),
    (["theory", "--f0", "1", "--diameter", "0"], "--diameter"),
    (["theory", "--f0", "1", "--fm", "0.5"], "--fm"),
    (["theory", "--f0", "1", "--fm", "nan"], "--fm"),
    (["theory"], "--f0"),
    # bench and the parser
    (["bench", "nosuch"], "nosuch"),
    (["bench", "mc", "--rounds", "0"], "--rounds"),
    (["bench", "solver", "--rounds", "101"], "--rounds"),
    (["bench", "mc", "--rounds", "two"], "--rounds"),
    (["bench", "shot", "--rounds", "2"], "--rounds"),
    (["bench", "mc", "--rounds", "1.5"], "--rounds"),
    (["bench", "solver", "--quick", "--baseline", "nosuchrev"], "nosuchrev"),
    (["bench", "mc", "--baseline", "nosuchrev"], "nosuchrev"),
    (["nosuch"], "nosuch"),
    # analyze, import, verify, ls (the archive and the analysis)
    (["analyze", "{d}/missing.isf", "--gauge-distance", "43 mm"], "missing.isf"),
    (["analyze", "{d}/empty.isf", "--gauge-distance", "43 mm"], "empty.isf"),
    (["analyze", "{d}/empty.isf", "--archive", "a.h5"], "rig analyze: error: unrecognized arguments: --archive a.h5"),
    (["analyze", "{d}/junk.isf", "--gauge-distance", "43 mm"], "junk.isf"),
    (["analyze", "{d}/folder", "--gauge-distance", "43 mm"], "folder"),
    (["analyze", "{d}/text.h5"], "text.h5"),
    (["analyze", "{d}/junk.isf", "--sensitivity", "1 kg"], "--sensitivity"),
    (["analyze", "{d}/missing.isf", "--gauge-distance", "nan"], "--gauge-distance"),
    (["import", "{d}/missing.isf", "--into", "{d}/a.h5"], "missing.isf"),
    (["import", "{d}/empty.csv", "--into", "{d}/a.h5"], "empty.csv"),
    (["import", "{d}/junk.isf", "--into", "{d}/a.h5"], "junk.isf"),
    (["verify", "{d}/missing.h5"], "missing.h5"),
    (["verify", "{d}/folder"], "folder"),
    (["ls", "{d}/missing.h5"], "missing.h5"),
    (["ls", "{d}/text.h5"], "text.h5"),
    (["ls", "{d}/folder"], "folder"),
]


def _argv(argv, d):
    return [a.replace("{d}", str(d)) for a in argv]


def one_line(err: str) -> str:
    lines = [line for line in err.splitlines() if line.strip()]
    assert len(lines) == 1, f"expected one line on stderr, got {len(lines)}:\n{err}"
    assert "Traceback" not in err
    return lines[0]


def test_the_corpus_is_large_enough():
    assert len(CASES) >= 60
    assert {_case(c)[0][0] for c in CASES} >= {"shot", "sweep", "mc", "animate", "reproduce", "theory",
                                               "bench", "analyze", "import", "verify", "ls"}


def _case(c):
    return c.values if hasattr(c, "values") else c


@pytest.mark.parametrize("argv,needle", CASES, ids=[" ".join(_case(c)[0])[:70] for c in CASES])
def test_bad_input_is_one_line_and_exit_2(tmp_path, monkeypatch, capsys, argv, needle):
    _files(tmp_path)
    monkeypatch.chdir(tmp_path)
    try:
        code = main(_argv(argv, tmp_path))
    except SystemExit as exc:  # argparse's own errors
        code = exc.code
    out = capsys.readouterr()
    line = one_line(out.err)
    assert code == 2, line
    assert needle in line, line
    assert (tmp_path / "existing.txt").read_text() == "already here\n"  # never overwritten


@pytest.mark.parametrize("argv,needle", [
    (["shot", S, "--set", "chain.colour=red"], "chain.colour"),
    (["theory", "--f0", "nan"], "--f0"),
    (["shot", S, "--export", "{d}/existing.txt", "--seed", "1"], "existing.txt"),
])
def test_the_real_entry_point(tmp_path, argv, needle):
    _files(tmp_path)
    r = subprocess.run([sys.executable, "-m", "rig.cli", *_argv(argv, tmp_path)], capture_output=True,
                       text=True, cwd=tmp_path, env={**os.environ}, timeout=300)
    assert r.returncode == 2
    assert needle in one_line(r.stderr)


def test_a_value_that_starts_with_a_dash_says_how_to_give_it(capsys):
    with pytest.raises(SystemExit) as exc:  # argparse's own error
        main(["analyze", "x.isf", "--gauge-distance", "-4mm"])
    assert exc.value.code == 2
    err = capsys.readouterr().err.strip()
    assert err == ("rig analyze: error: argument --gauge-distance: expected one argument (a value that starts "
                   "with '-' is written --gauge-distance=VALUE)")
    assert main(["analyze", "x.isf", "--gauge-distance=-4mm"]) == 2
    assert "--gauge-distance = -0.004: a finite number > 0 m" in capsys.readouterr().err
