"""The generated bad-input corpus: every scene key with the values that are wrong for it,
every command's options with wrong values and combinations that would be ignored, the
Python API's constructors with wrong types, and damaged scope files.

A case on the command line ends in exactly one line on stderr that names the field (or
the file), exit 2, no traceback; a case of the API raises RigError or InstrumentError with
a one-line message naming the field. Every case is refused before anything is solved: the
solver's entry points are replaced by a trap for the whole module, which also keeps the
corpus fast (tests/cli/test_bad_inputs.py holds the hand-written cases, some of which
solve)."""
from __future__ import annotations

import math
import re

import pytest

from instruments.errors import InstrumentError
from rig.cli import main
from rig.errors import RigError
from rig.experiment.scene import SCHEMA

S = "ptfe52_magnetic"
VEL = "striker.velocity=normal(0.89 m/s, 0.01 m/s)"
YM = "chain.youngs_modulus=0.4 GPa:2 GPa"


def _keys(node=SCHEMA, prefix=""):
    """(dotted key, spec) of every scene key, '*' tables taken as this scene's gauges.upper
    and scope.channels.CH1."""
    for name, spec in node.items():
        name = {"gauges.*": "gauges.upper", "scope.channels.*": "scope.channels.CH1"}.get(prefix + name, prefix + name)
        if isinstance(spec, dict):
            yield from _keys(spec, name + ".")
        else:
            yield name, spec


NOT_ONE_NUMBER = ["2.3.8", "1.000.000", "2*0.5", "1/2", "0.5(2)", "2**-1", "1e-1.5", "\u0661", "\uff11"]
"""Texts that are not one number (several dots, arithmetic, a fractional exponent, digits of
another script): they had been read as a product (2.3 x 0.8), an expression or a 1."""
WRONG_UNIT = {"kg": "1 m", "m": "1 kg"}  # a quantity of another dimension
POSITIVE = {"chain.diameter", "chain.mass", "chain.reference_force", "chain.youngs_modulus",
            "chain.magnetic_youngs_modulus", "striker.mass", "striker.velocity", "striker.diameter",
            "holder.bore", "holder.outer_diameter", "holder.length", "wall.plate_mass", "wall.rod_stiffness",
            "wall_sensor.sensitivity", "gauges.upper.sensitivity", "gauges.upper.mass", "scope.sample_interval",
            "scope.channels.CH1.volts_per_div", "solver.duration", "solver.sample_interval",
            "scope.channels.CH1.bandwidth"}
"""Quantity keys that are refused at 0 and below."""
ZERO_ALLOWED = {"chain.previous_shots"}
"""Whole-number keys whose 0 is allowed (no earlier shot on the chain); 101 is their bad case."""
CHOICES = ("chain.material", "chain.contact_law", "striker.material", "wall.material", "scope.mode",
           "scope.trigger.source", "scope.trigger.slope", "scope.channels.CH1.coupling",
           "solver.method", "gauges.upper.channel", "wall_sensor.channel")
"""Text keys with a fixed set of values."""


def _scene_cases():
    """(--set item, what the line must name) for every key and its wrong values."""
    for key, spec in _keys():
        if isinstance(spec, str):  # a quantity
            bad = ["nan", "inf", "-inf", "abc", "", "1,2", f"1,5 {spec}", f"1 200 {spec}", "1_000", "1e999",
                   f"nan {spec}", WRONG_UNIT.get(spec, "1 kg")]
            bad += ["0", "-1", f"-3 {spec}"] if key in POSITIVE else []
            bad += [f"{text} {spec}" for text in NOT_ONE_NUMBER]
        elif spec is int:
            bad = ["2.5", "abc", "", "1,0", "1 000", "nan", "inf", "-1", "true"] + NOT_ONE_NUMBER
            bad += ["101"] if key in ZERO_ALLOWED else ["0"]
        elif spec is float:
            bad = ["abc", "", "0,5", "nan", "inf", "1 m", "1_0"] + NOT_ONE_NUMBER
        elif spec is bool:
            bad = ["maybe", "1", "", "yes"]
        elif key in CHOICES:
            bad = ["nosuch", ""]
        else:
            continue
        for value in bad:
            yield f"{key}={value}", key


SCENE_CASES = list(_scene_cases())


def _flag_cases():
    """(argv, what the line must name): each command's options with wrong values, and options
    given where they do nothing."""
    out = "{d}/o"
    cases = []
    comma = ["1,5", "1 000", "1_000", "nan", "abc", "", "-1"]
    for count in comma + ["0", "2.5"]:
        cases += [(["mc", S, "--shots", count, "--vary", VEL, "--out", out], "--shots"),
                  (["mc", S, "--shots", "8", "--batch", count, "--vary", VEL, "--out", out], "--batch"),
                  (["mc", S, "--shots", "8", "--workers", count, "--vary", VEL, "--out", out], "--workers"),
                  (["fit", S, "--param", YM, "--points", "p.csv", "--max-evaluations", count, "--out", out],
                   "--max-evaluations"),
                  (["fit", S, "--param", YM, "--points", "p.csv", "--posterior", count, "--out", out], "--posterior"),
                  (["bench", "mc", "--rounds", count], "--rounds")]
    for seed in comma + ["2.5", str(2**63)]:
        cases += [(["shot", S, "--seed", seed], "--seed"), (["sweep", S, "--vary", "striker.velocity=1:2:2",
                                                           "--seed", seed], "--seed"),
                  (["mc", S, "--shots", "8", "--vary", VEL, "--seed", seed, "--out", out], "--seed"),
                  (["animate", S, "--out", "{d}/m.gif", "--seed", seed], "--seed")]
    for share in ["5,5%", "1 0%", "nan", "abc", "", "-1%", "101%", "1.5"]:
        cases.append((["mc", S, "--shots", "8", "--vary", VEL, "--max-failed", share, "--out", out], "--max-failed"))
    for seconds in ["1,5", "0", "-1", "nan", "inf", "abc", ""]:
        cases.append((["mc", S, "--shots", "8", "--vary", VEL, "--scheduler", "local", "--worker-timeout", seconds,
                       "--out", out], "--worker-timeout"))
    for value in ["1,5", "1_0", "abc", "", "nan", "0", "-1", "1e-20", "1"]:
        cases.append((["mc", S, "--shots", "8", "--vary", VEL, "--accuracy", value, "--out", out], "accuracy"))
    for value in ["1,5", "1_0", "abc", "", "nan", "inf", "0", "-2"]:
        cases += [(["animate", S, "--out", "{d}/m.gif", "--exaggerate", value], "--exaggerate"),
                  (["analyze", "x.isf", "--beta", value], "--beta")]
    for value in ["1,5", "1_0", "abc", "", "0", "1", "-2", "2.5"]:
        cases.append((["animate", S, "--out", "{d}/m.gif", "--frames", value], "--frames"))
    for flag, unit in (("--gauge-distance", "m"), ("--sensitivity", "V/N"), ("--tau", "s"), ("--f0", "N"),
                       ("--diameter", "m")):
        for value in ["1,5", f"1,5 {unit}", f"1 200 {unit}", "1_0", "abc", "", "nan", "1 J"]:
            cases.append((["analyze", "x.isf", f"{flag}={value}"], flag))
    for flag in ("--f0", "--fm", "--diameter"):
        for value in ["1,5", "1,5 N", "1 200", "1_0", "abc", "nan", "1 s"]:
            argv = ["theory", "--f0", "1", flag, value] if flag != "--f0" else ["theory", "--f0", value]
            cases.append((argv, flag))
    for value in ["striker.velocity=0,3:1.5:7", "striker.velocity=0.3:1,5:7", "striker.velocity=0.3:1.5:7,0",
                  "striker.velocity=0.3 m/s:1 200 m/s:3", "striker.velocity=0.3:1.5:1_0",
                  "striker.velocity=0.3 kg:1.5 kg:3", "striker.velocity=0.3:1.5:-2", "striker.velocity=:1:3",
                  "striker.velocity=0.3:1.5:3:4", "chain.beads=20:30:4", "chain.beads=20.5:30:3",
                  "gauges.upper.bead=3:5:4", "scope.record_length=1000.5:2000:3", "chain.material=1:2:3",
                  "chain.poisson_ratio=0,2:0.3:2", "chain.poisson_ratio=a:b:2", "striker.velocity=inf:1:2",
                  "solver.duration=0:1:2", "nosuch.key=1:2:3", "chain=1:2:3"]:
        cases.append((["sweep", S, "--vary", value], "--vary"))
    for value in ["striker.velocity=normal(0,89 m/s, 0,01 m/s)", "striker.velocity=normal(0.89 m/s, 0,01 m/s)",
                  "striker.velocity=normal(0.89, 0.01)", "striker.velocity=normal(1 200 m/s, 1 m/s)",
                  "striker.velocity=uniform(1 m/s)", "striker.velocity=uniform(2 m/s, 1 m/s)",
                  "striker.velocity=normal(nan m/s, 1 m/s)", "striker.velocity=weibull(1, 2)",
                  "striker.velocity=normal(0.89 m/s, 0 m/s)", "gauges.upper.gain=lognormal(1, 0,6)",
                  "gauges.upper.gain=lognormal(1,5, 0.6)", "gauges.upper.gain=lognormal(-1, 0.6)",
                  "chain.bead_mass=normal(0.1226 g, 1 m)", "solver.accuracy=normal(1e-4, 1e-5)",
                  "striker.velocity", "=normal(1, 1)", "striker.velocity=truncnormal(1 m/s, 1 m/s, 2 m/s, 1 m/s)"]:
        cases.append((["mc", S, "--shots", "8", "--vary", value, "--out", out], "--vary"))
    for value in ["chain.youngs_modulus=0,4 GPa:2 GPa", "chain.youngs_modulus=0.4 GPa:2,0 GPa",
                  "chain.youngs_modulus=1 200 MPa:2 GPa", "chain.youngs_modulus=0.4:2",
                  "chain.youngs_modulus=2 GPa:1 GPa",
                  "chain.youngs_modulus=0.4 GPa", "chain.youngs_modulus=0.4 m:2 m", "chain.contact_exponent=1,2:2.4",
                  "chain.contact_exponent=1.2:2,4", "chain.contact_exponent=a:b", "chain.contact_exponent=1.2 m:2",
                  "chain.material=a:b", "nosuch=1:2", "chain.damping_time=0 s:1 ms",
                  "chain.youngs_modulus=nan GPa:2 GPa"]:
        cases.append((["fit", S, "--param", value, "--points", "p.csv", "--out", out], "--param"))
    for text in NOT_ONE_NUMBER:  # one number in every command, every kind of value
        cases += [(["shot", S, "--set", f"magnet.force={text} N"], "magnet.force"),
                  (["sweep", S, "--vary", "striker.velocity=0.3:1.5:3", "--set", f"magnet.force={text} N"],
                   "magnet.force"),
                  (["mc", S, "--shots", "8", "--vary", VEL, "--set", f"striker.mass={text} g", "--out", out],
                   "striker.mass"),
                  (["fit", S, "--param", YM, "--points", "p.csv", "--set", f"magnet.force={text} N", "--out", out],
                   "magnet.force"),
                  (["animate", S, "--out", "{d}/m.gif", "--set", f"striker.velocity={text} m/s"], "striker.velocity"),
                  (["theory", "--f0", "1", "--diameter", f"{text} mm"], "--diameter"),
                  (["theory", "--f0", f"{text}"], "--f0"),
                  (["analyze", "x.isf", f"--gauge-distance={text} mm"], "--gauge-distance"),
                  (["analyze", "x.isf", f"--beta={text}"], "--beta"),
                  (["animate", S, "--out", "{d}/m.gif", "--frames", text], "--frames"),
                  (["mc", S, "--shots", "8", "--vary", f"striker.velocity=normal({text} m/s, 0.01 m/s)", "--out", out],
                   "--vary"),
                  (["sweep", S, "--vary", f"striker.velocity={text}:1.5:3"], "--vary"),
                  (["fit", S, "--param", f"chain.youngs_modulus={text} GPa:4 GPa", "--points", "p.csv", "--out", out],
                   "--param")]
    # a solver.sample_interval coarser than the scope's: the scope would read lines drawn between the solver's
    # samples (had exited 0 with F_d 21 % low); refused before anything is solved, by every command that fires
    for value in ["0.5 us", "20 us", "50 us", "1 ms"]:
        cases += [(["shot", S, "--set", f"solver.sample_interval={value}"], "solver.sample_interval"),
                  (["sweep", S, "--vary", "striker.velocity=0.5:1:2", "--set", f"solver.sample_interval={value}"],
                   "solver.sample_interval"),
                  (["mc", S, "--shots", "8", "--vary", VEL, "--set", f"solver.sample_interval={value}", "--out", out],
                   "solver.sample_interval")]
    cases.append((["sweep", S, "--vary", "solver.sample_interval=0.1 us:50 us:3"], "solver.sample_interval"))
    # options given where they do nothing
    cases += [
        (["shot", S, "--format", "csv"], "--format"),
        (["sweep", S, "--vary", "striker.velocity=0.3:1:2", "--vary", "chain.beads=20:30:3"], "--vary"),
        (["fit", S, "--param", YM, "--points", "p.csv", "--shot", "2", "--out", out], "--shot"),
        (["fit", S, "--param", YM, "--records", "a.isf", "--shot", "1", "--out", out], "--shot"),
        (["fit", S, "--param", YM, "--points", "p.csv", "--walkers", "8", "--out", out], "--walkers"),
        (["fit", S, "--param", YM, "--points", "p.csv", "--seed", "3", "--out", out], "--seed"),
        (["fit", S, "--param", YM, "--points", "p.csv", "--archive", "a.h5", "--out", out], "--archive"),
        (["mc", S, "--shots", "8", "--vary", VEL, "--worker-timeout", "5", "--out", out], "--worker-timeout"),
        (["mc", S, "--shots", "8", "--vary", VEL, "--workers", "2", "--scheduler", "tcp://127.0.0.1:1", "--out", out],
         "--workers"),
        (["import", "a.isf", "--together", "--into", "a.h5"], "--together"),
        (["bench", "shot", "--quick"], "--quick"),
        (["bench", "archive", "--quick"], "--quick"),
        (["bench", "startup", "--quick"], "--quick"),
        (["bench", "shot", "--peers"], "--peers"),
        (["bench", "fit", "--baseline", "HEAD"], "--baseline"),
        (["bench", "models", "--rounds", "2"], "--rounds"),
        (["bench", "shot", "--cold"], "--cold"),
        (["bench", "startup", "--rounds", "2"], "--rounds"),
        (["analyze", "x.isf", "--shot", "1"], "--shot"),
        (["analyze", "x.isf", "--shot", "-1"], "--shot"),
        (["analyze", "x.isf", "--shot", "1,0"], "--shot"),
        # a key given twice: the last had won silently, or the --set was ignored
        (["sweep", S, "--vary", "striker.velocity=0.3:1.5:3", "--set", "striker.velocity=1 m/s"], "--vary"),
        (["fit", S, "--param", "chain.youngs_modulus=0.2 GPa:4 GPa", "--set", "chain.youngs_modulus=1 GPa",
          "--points", "p.csv", "--out", out], "--param"),
        (["fit", S, "--param", "chain.damping_time=0.1 ms:1 ms", "--set", "chain.contact_law=hertz", "--points",
          "p.csv", "--out", out], "switches chain.contact_law to kuwabara-kono"),
    ]
    # a mass in grams given as kilograms: a bead 1000 times its sphere's mass (it had fired with NO TRIGGER, exit 0)
    cases += [(["shot", S, "--set", "chain.mass=0.1226"], "chain.mass = 0.1226: a ptfe sphere of 4.76 mm weighs"),
              (["shot", S, "--set", "gauges.upper.mass=0.116"], "gauges.upper.mass = 0.116: a ptfe sphere"),
              (["shot", S, "--set", "chain.mass=0.1226 mg"], "chain.mass = 1.226e-07")]
    # a Kuwabara-Kono damping time of 1 s: the viscous flow's substeps (256846 a step) had run 86 s unannounced
    cases += [(["shot", S, "--set", "chain.contact_law=kuwabara-kono", "--set", "chain.damping_time=1 s"],
               "substeps of the viscous flow each")]
    # 10,000 frames: a .gif's frames held in memory (45 GB) had died out of memory; a .mp4's render time announced
    cases += [(["animate", S, "--frames", "10000", "--out", "{d}/m.gif"], "a .gif holds every frame until it is"),
              (["animate", S, "--frames", "10000", "--out", "{d}/m.mp4"], "beyond the limit of 120 s; add --allow")]
    # rig reproduce: a noise seed or draws without the study that draws noise; a study of 330 days unannounced
    cases += [(["reproduce", "daraio2006", "--out", out, "--seed", "3"], "--seed = 3: only with --identifiability"),
              (["reproduce", "daraio2006", "--out", out, "--draws", "5"], "--draws = 5: only with --identifiability"),
              (["reproduce", "daraio2006", "--out", out, "--identifiability", "--draws", "1000000"],
               "--draws = 1000000: the identifiability study would take 5000000 fits")]
    # the fitted families' search: a flag of --fitted without it, a seed that seeds nothing, no generations
    cases += [(["reproduce", "daraio2006", "--out", out, "--starts", "3"], "--starts = 3: only with --fitted"),
              (["reproduce", "daraio2006", "--out", out, "--global-search", "5"],
               "--global-search = 5: only with --fitted"),
              (["reproduce", "daraio2006", "--out", out, "--fitted", "--global-search", "0"],
               "a whole number of generations from 1 to 1000"),
              (["fit", S, "--param", YM, "--points", "p.csv", "--out", out, "--seed", "3"],
               "--seed = 3: needs --posterior STEPS or --global-search GENERATIONS")]
    # an empty path: rig mc had written into the current folder, rig shot had archived nothing with exit 0
    cases += [(["shot", S, "--out", ""], "--out = '': an empty path"),
              (["shot", S, "--export", " "], "--export = ' ': an empty path"),
              (["mc", S, "--shots", "8", "--vary", VEL, "--out", ""], "--out = '': an empty path"),
              (["import", "a.isf", "--into", ""], "--into = '': an empty path"),
              (["analyze", "", "--gauge-distance", "43 mm"], "FILE = '': an empty path"),
              (["import", "", "--into", "a.h5"], "FILE = '': an empty path")]
    mass = "chain.mass=normal(0.1226 g, 0.001 g)"
    cases += [(["mc", S, "--shots", "8", "--vary", mass, "--vary", "chain.bead_mass=normal(0.1226 g, 0.001 g)",
                "--out", out], "--vary = 'chain.bead_mass': names the quantity chain.mass names too")]
    twice = ["--set", "striker.velocity=1", "--set", "striker.velocity = 2 m/s"]
    cases += [(["shot", S, *twice], "set twice"),
              (["sweep", S, "--vary", "chain.beads=20:30:3", *twice], "set twice"),
              (["mc", S, "--shots", "8", "--vary", "striker.mass=normal(1.2 g, 0.01 g)", *twice, "--out", out],
               "set twice"),
              (["fit", S, "--param", YM, "--points", "p.csv", *twice, "--out", out], "set twice"),
              (["animate", S, "--out", "{d}/m.gif", *twice], "set twice")]
    return cases


FLAG_CASES = _flag_cases()


def _isf(points=4, ymult="1E-3", xincr="1E-6", nr_pt=None, byt_nr="1", curve=None, header_extra="") -> bytes:
    """An ISF file (8-bit codes) whose fields a case spoils."""
    data = bytes(range(points)) if curve is None else curve
    nr = points if nr_pt is None else nr_pt
    head = (f':WFMPRE:BYT_NR {byt_nr};BIT_NR 8;ENCDG BIN;BN_FMT RI;BYT_OR MSB;NR_PT {nr};WFID "Ch1, DC coupling";'
            f'PT_FMT Y;XUNIT "s";XINCR {xincr};XZERO 0;PT_OFF 0;YUNIT "V";YMULT {ymult};YOFF 0;YZERO 0;'
            f'{header_extra}:CURVE #{len(str(len(data)))}{len(data)}')
    return head.encode() + data


CSV_HEAD = "Record Length,4,,\nSample Interval,1e-06,,\nTrigger Point,0,,\nSource,CH1,,\n"
SCOPE_FILES = {
    "one_point.isf": _isf(points=1),
    "ymult_zero.isf": _isf(ymult="0"),
    "ymult_nan.isf": _isf(ymult="NAN"),
    "ymult_text.isf": _isf(ymult="abc"),
    "xincr_zero.isf": _isf(xincr="0"),
    "xincr_negative.isf": _isf(xincr="-1E-6"),
    "xincr_text.isf": _isf(xincr="fast"),
    "byt_nr_3.isf": _isf(byt_nr="3"),
    "nr_pt_mismatch.isf": _isf(nr_pt=8),
    "nr_pt_text.isf": _isf(nr_pt="many"),
    "truncated.isf": _isf(points=100)[:-50],
    "no_curve.isf": _isf().split(b":CURVE")[0],
    "bad_block.isf": _isf().replace(b":CURVE #14", b":CURVE #x4"),
    "not_ascii.isf": b":WFMPRE:BYT_NR 1;\xff\xfe\x00;NR_PT 4:CURVE #14abcd",
    "missing_ymult.isf": _isf().replace(b"YMULT 1E-3;", b""),
    "empty.isf": b"",
    "text_in_data.csv": (CSV_HEAD + ",,0.0,0.1\n,,1e-6,abc\n,,2e-6,0.2\n,,3e-6,0.3\n").encode(),
    "empty.csv": b"",
    "only_header.csv": CSV_HEAD.encode(),
    "binary.csv": bytes(range(256)) * 8,
    "nan_time.csv": (CSV_HEAD + ",,nan,0.0\n,,nan,0.1\n,,nan,0.2\n,,nan,0.3\n").encode(),
    "one_row.csv": (CSV_HEAD.replace("Record Length,4", "Record Length,1") + ",,0.0,0.1\n").encode(),
    "junk.wfm": b"\x00\x01garbage" * 64,
    # a header Sample Interval the TIME column contradicts, in each CSV layout
    "interval_dpo.csv": b"Sample Interval,2e-06\nRecord Length,4\nTIME,CH1\n0,0.1\n1e-06,0.2\n2e-06,0.3\n3e-06,0.4\n",
    "interval_tds.csv": (b"Record Length,4,,0.0,0.1\nSample Interval,2e-06,,1e-06,0.2\nTrigger Point,0,,2e-06,0.3\n"
                         b"Source,CH1,,3e-06,0.4\n"),
    # other makers' CSV exports, named; a spreadsheet's re-save, named
    "siglent.csv": b"Record Length,Analog:4,\nSample Interval,Analog:1e-06,\nSecond,Volt,\n0,0.1,\n1e-06,0.2,\n",
    "lecroy.csv": b"LECROYWS3024,23052,Waveform\nSegments,1,SegmentSize,4\nTime,Ampl\n0,0.1\n1e-06,0.2\n",
    "resaved.csv": b"Sample Interval;0,000001\nTIME;CH1\n0,000000;0,1\n0,000001;0,2\n0,000002;0,3\n",
    # an ISF header whose encoding contradicts its curve, both ways
    "asc_over_bin.isf": _isf().replace(b"ENCDG BIN", b"ENCDG ASC"),
    "bin_over_asc.isf": _isf().split(b"#14")[0] + b"1,2,3,4\n",
    "ascii_curve_short.isf": _isf().replace(b"ENCDG BIN", b"ENCDG ASC").split(b"#14")[0] + b"1,2,3\n",
    # a header with a field that is no number, given twice, or off the converter's range
    "xzero_nan.isf": _isf().replace(b"XZERO 0;", b"XZERO NAN;"),
    "ymult_twice.isf": _isf(header_extra="YMULT 2E-3;"),
    "yoff_huge.isf": _isf().replace(b"YOFF 0;", b"YOFF 1e300;"),
    "bn_fmt_fp.isf": _isf().replace(b"BN_FMT RI", b"BN_FMT FP"),
    # a CSV cut short at a line boundary, or whose Record Length lies
    "cut_dpo.csv": b"Record Length,12\nSample Interval,1e-06\nTIME,CH1\n0,0.1\n1e-06,0.2\n2e-06,0.3\n3e-06,0.4\n",
    "record_length_lies.csv": (b"Record Length,99999999\nSample Interval,1e-06\nTIME,CH1\n0,0.1\n1e-06,0.2\n"
                               b"2e-06,0.3\n3e-06,0.4\n"),
    # records that are no analog volts, as CSV (the .wfm and .isf forms: tests/instruments/test_record_kinds.py)
    "digital.csv": (b"Waveform Type,DIGITAL\nSample Interval,1e-06\nRecord Length,2\nTIME,CH1_D0,CH1_D1\n"
                    b"0,0,1\n1e-06,1,1\n"),
    "iq.csv": (b"Waveform Type,IQ\nIQ_centerFrequency,1e9\nIQ_span,1e6\nSample Interval,1e-06\nTIME,CH1\n"
               b"0,1\n1e-06,2\n"),
}
FILE_CASES = [(cmd, name) for name in SCOPE_FILES for cmd in ("analyze", "import")]


@pytest.fixture(autouse=True)
def no_solve(monkeypatch):
    """A bad input is refused before anything is solved: every solver entry point is a trap."""
    import rig.fit.evaluate
    import rig.solver.control
    import rig.study.batch

    def trap(*args, **kwargs):
        raise AssertionError("solved: a bad input must be refused before any solve")

    monkeypatch.setattr(rig.solver.control, "integrate_one", trap)
    for module in (rig.fit.evaluate, rig.study.batch):
        monkeypatch.setattr(module, "solve_ensemble", trap)


def _line(capsys) -> str:
    err = capsys.readouterr().err
    lines = [line for line in err.splitlines() if line.strip()]
    assert len(lines) == 1, f"expected one line on stderr, got {len(lines)}:\n{err}"
    assert "Traceback" not in err
    return lines[0]


def _run(argv, d) -> int:
    try:
        return main([a.replace("{d}", str(d)) for a in argv])
    except SystemExit as exc:  # argparse's own refusal
        return exc.code


def test_the_corpus_holds_300_cases_over_every_command_and_key():
    total = len(SCENE_CASES) + len(FLAG_CASES) + len(FILE_CASES) + len(API_CASES)
    assert total >= 300, total
    keys = {k for k, spec in _keys() if isinstance(spec, str) or spec in (int, float, bool)}
    assert keys <= {key for _, key in SCENE_CASES}  # every numeric and true/false key
    assert {argv[0] for argv, _ in FLAG_CASES} >= {"shot", "sweep", "mc", "fit", "animate", "analyze", "theory",
                                                    "bench"}


@pytest.mark.parametrize("item,key", SCENE_CASES, ids=[c[0] for c in SCENE_CASES])
def test_a_wrong_scene_value_is_one_line_naming_its_key(tmp_path, monkeypatch, capsys, item, key):
    monkeypatch.chdir(tmp_path)
    assert _run(["shot", S, "--set", item], tmp_path) == 2
    line = _line(capsys)
    assert key in line, line
    value = item.split("=", 1)[1]
    if re.search(r"\d,\d", value):
        assert "use a decimal point" in line, line
    elif re.search(r"\d[ _]\d", value):
        assert "no thousands separator" in line, line
        assert re.sub(r"(\d)[ _](?=\d)", r"\1", value).split()[0] in line, line  # the example is its own number


@pytest.mark.parametrize("argv,needle", FLAG_CASES, ids=[" ".join(c[0])[:80] for c in FLAG_CASES])
def test_a_wrong_option_is_one_line_naming_it(tmp_path, monkeypatch, capsys, argv, needle):
    monkeypatch.chdir(tmp_path)
    assert _run(argv, tmp_path) == 2
    line = _line(capsys)
    assert needle in line, line


@pytest.mark.parametrize("command,name", FILE_CASES, ids=[f"{c} {n}" for c, n in FILE_CASES])
def test_a_damaged_scope_file_is_one_line_naming_it(tmp_path, monkeypatch, capsys, command, name):
    monkeypatch.chdir(tmp_path)
    (tmp_path / name).write_bytes(SCOPE_FILES[name])
    argv = [command, name] + (["--into", "a.h5"] if command == "import" else ["--gauge-distance", "43 mm"])
    assert _run(argv, tmp_path) == 2
    line = _line(capsys)
    assert name in line, line
    assert not (tmp_path / "a.h5").exists() or command != "import"  # nothing half-imported


def _api_cases():
    """(callable, what the message must name)."""
    from rig.experiment.shot import Rig
    from rig.model.chain import Chain
    from rig.model.parts import Bead, Striker, Wall
    from rig.solver.saveat import SaveAt
    from rig.solver.solve import solve

    def chain():
        return Chain([Bead("ptfe", 4.76e-3)] * 5, striker=Striker(), wall=Wall())
    cases = [(lambda a=a: Rig.from_scene(a), "scene") for a in (None, 3, 2.5, "", [S], b"ptfe52_magnetic")]
    cases += [(lambda o=o: Rig.from_scene(S, o), "overrides") for o in (None, "striker.velocity=1", [1], [None])]
    cases += [(lambda s=s: Rig(s), "scene") for s in (None, S, {})]
    cases += [(lambda v=v: Striker(velocity=v), "striker.velocity")
              for v in (0, -1, math.nan, math.inf, 1e-300, "1,2 m/s", "1 kg", None, True)]
    cases += [(lambda v=v: Striker(mass=v), "striker.mass") for v in (0, -1, math.nan, "0,47 g", "1 m")]
    cases += [(lambda v=v: Bead("ptfe", v), "diameter") for v in (0, -1, math.nan, "4,76 mm", "1 kg", None)]
    cases += [(lambda v=v: Bead(v, 4.76e-3), "material") for v in ("wood", 3, None)]
    cases += [(lambda v=v: Bead("ptfe", 4.76e-3, v), "bead.mass = ") for v in (0.1226, 1e-7, "0.1226 kg")]
    cases += [(lambda b=b: Chain(b), "beads") for b in ([], None, 3, ["ptfe"])]
    cases += [(lambda t=t: solve(chain(), t), "t_end") for t in (0, -1, math.nan, math.inf, "1 ms", None)]
    cases += [(lambda m=m: solve(chain(), 1e-4, method=m), "method") for m in ("euler", 3)]
    cases += [(lambda a=a: solve(chain(), 1e-4, accuracy=a), "accuracy") for a in (0, -1, math.nan, 5, "1e-4")]
    cases += [(lambda s=s: solve(chain(), 1e-4, save=s), "save") for s in ("all", 3, {"c": 1})]
    cases += [(lambda h=h: SaveAt({"c": chain().contact_probe(2)}, sample_interval=h), "sample_interval")
              for h in (0, -1, math.nan, math.inf, "1 us", None)]
    cases += [(lambda p=p: SaveAt(p), "probes") for p in (None, 3, "c", {"c": 3})]
    cases += [(lambda x=x: Chain([Bead("ptfe", 4.76e-3)] * 5, striker=x), "striker") for x in ("fast", 3)]
    from instruments.archive import Archive
    cases += [(lambda x=x: Archive("shots.h5").read(x), "shot_id") for x in ("1", 1.0, 0, True, None)]
    return cases


API_CASES = _api_cases()


@pytest.mark.parametrize("case", range(len(API_CASES)))
def test_a_wrong_argument_to_the_api_raises_one_line(case):
    call, needle = API_CASES[case]
    with pytest.raises((RigError, InstrumentError)) as exc:
        call()
    message = str(exc.value)
    assert "\n" not in message and needle in message, message


@pytest.mark.parametrize("name,defect", [
    ("one_point.isf", "NR_PT = 1: a record needs at least 2 points"),  # had been "another time base than ..."
    ("ymult_zero.isf", "YMULT = 0.0: the volts per code must be a finite number other than 0"),
    ("ymult_nan.isf", "YMULT = nan"),
])
def test_a_record_without_a_time_base_or_a_scale_names_the_header_field(tmp_path, capsys, name, defect):
    path = tmp_path / name
    path.write_bytes(SCOPE_FILES[name])
    assert _run(["analyze", str(path), "--gauge-distance", "43 mm"], tmp_path) == 2
    line = _line(capsys)
    assert str(path) in line and defect in line, line
