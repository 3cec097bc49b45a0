"""The rig command line: public JSON keys, readable output, clean errors."""
import json

import pytest

from rig.bench.solver import at_equal_error, equal_error_rounds, interleaved, median_rows
from rig.cli import main


def _json(capsys, *argv):
    assert main(list(argv)) == 0
    return json.loads(capsys.readouterr().out)


def test_theory_json_keys_and_values(capsys):
    out = _json(capsys, "theory", "--material", "ptfe", "--diameter", "4.76mm", "--f0", "0.017",
                "--fm", "5", "--json")
    assert out["sound_speed_m_per_s"] == pytest.approx(92.6, rel=1e-3)
    for key in ("speed_m_per_s", "sonic_vacuum_speed_m_per_s", "discrete_speed_m_per_s"):
        assert out[key] > out["sound_speed_m_per_s"]
    assert out["discrete_speed_m_per_s"] == pytest.approx(out["speed_m_per_s"], rel=0.02)


def test_theory_gives_each_contacts_yield_force_at_one_pressure(capsys):
    """--yield-force is the bead-bead force; the pressure it is gives each partner its own
    force, F_y = pi^3 R*^2 p_y^3 / (6 E*^2): the chain against the same computed by the
    model for a published scene's contacts (magnetic bead, PTFE, brass wall)."""
    from rig.experiment.shot import Rig

    out = _json(capsys, "theory", "--material", "ptfe", "--diameter", "4.76mm", "--f0", "0.017",
                "--yield-force", "0.8 N", "--json")
    forces = out["yield_force_N"]
    assert forces["another bead"] == pytest.approx(0.8, rel=1e-12)
    chain = Rig.from_scene("ptfe52_magnetic", ("chain.contact_law=thornton", "chain.yield_force=0.8 N")).chain
    model = chain.contact_yield_forces()
    assert forces["the magnetic bead (chrome steel, 5 mm)"] == pytest.approx(model[1], rel=1e-9)
    assert forces["the wall (brass, flat)"] == pytest.approx(model[chain.n_beads], rel=1e-9)
    again = _json(capsys, "theory", "--material", "ptfe", "--f0", "0.017", "--yield-pressure",
                  f"{out['yield_pressure_Pa']!r} Pa", "--json")
    assert again["yield_force_N"] == pytest.approx(forces, rel=1e-12)


def test_theory_without_fm_prints_only_the_sound_speed(capsys):
    out = _json(capsys, "theory", "--material", "steel316", "--f0", "2.44 N", "--json")
    assert out["sound_speed_m_per_s"] == pytest.approx(539.6, rel=1e-3)
    assert out["speed_m_per_s"] is None and out["discrete_speed_m_per_s"] is None


def test_theory_discrete_over_eq4_is_one_ratio_at_every_diameter(capsys):
    ratios = []
    for diameter in ("0.01 mm", "0.1 mm", "4.76 mm", "10 cm"):  # forces with the bead's cross-section
        scale = (float(diameter.split()[0]) * (1 if diameter.endswith("cm") else 0.1) / 0.476) ** 2
        out = _json(capsys, "theory", "--diameter", diameter, "--f0", str(0.062 * scale), "--fm", str(20 * scale),
                    "--json")
        ratios.append(out["discrete_speed_m_per_s"] / out["sonic_vacuum_speed_m_per_s"])
        assert out["discrete_lab_speed_m_per_s"] < out["discrete_speed_m_per_s"]  # the spacing is a - overlap
    assert max(ratios) - min(ratios) < 1e-3 * ratios[0], ratios
    assert ratios[0] == pytest.approx(1.0287, abs=1e-3)


@pytest.mark.parametrize("argv,keys,why", [
    (["--diameter", "1e-30", "--f0", "0.062", "--fm", "20"], ["sound_speed_m_per_s", "discrete_speed_m_per_s"],
     "overlap"),
    (["--diameter", "1um", "--f0", "0.062", "--fm", "20"], ["speed_m_per_s", "discrete_speed_m_per_s"], "overlap"),
    (["--f0", "1e-300", "--fm", "1e300"], ["sonic_vacuum_speed_m_per_s", "discrete_speed_m_per_s"], "overlap"),
    (["--f0", "19.99", "--fm", "20"], ["discrete_speed_m_per_s"], "Fm/F0 = 1.001"),
    (["--f0", "1"], ["speed_m_per_s", "discrete_speed_m_per_s"], "no --fm"),
])
def test_theory_gives_the_reason_of_every_figure_it_cannot_compute(capsys, argv, keys, why):
    """A figure is a speed the chain can have or null with its reason: never a negative
    speed, a blank without a word or a warning on stderr."""
    out = _json(capsys, "theory", *argv, "--json")
    for key in keys:
        assert out[key] is None and why in out["reasons"][key], out
    for key, value in out.items():
        if key.endswith("_m_per_s"):
            assert (value is None) == (key in out["reasons"]) and (value is None or value > 0), out
    assert main(["theory", *argv]) == 0
    captured = capsys.readouterr()
    assert why in captured.out and captured.err == ""


@pytest.mark.parametrize("argv,field", [
    (["theory", "--material", "wood", "--f0", "1"], "material"),
    (["theory", "--f0", "-1"], "--f0"),
    (["theory", "--f0", "1", "--fm", "0.5"], "--fm"),
    (["theory", "--f0", "1", "--diameter", "4.76 kg"], "--diameter"),
    (["shot", "ptfe52_magnetic", "--set", "striker.velocity=-1"], "striker.velocity"),
    (["shot", "ptfe52_magnetic", "--set", "chain.colour=red"], "chain.colour"),
    (["shot", "no_such_scene"], "scene"),
])
def test_bad_input_is_one_line_and_exit_2(capsys, argv, field):
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert field in err and "\n" not in err and "Traceback" not in err


def test_work_precision_at_equal_error():
    # each method's CPU at an error level, interpolated log-log between its runs around it
    rows = [dict(scenario="s", method="srkn6b", setting="a", cpu_s=0.05, error=1e-3),
            dict(scenario="s", method="srkn6b", setting="b", cpu_s=0.1, error=1e-5),
            dict(scenario="s", method="scipy-DOP853", setting="c", cpu_s=1.0, error=1e-3),
            dict(scenario="s", method="scipy-DOP853", setting="d", cpu_s=4.0, error=1e-5),
            dict(scenario="s", method="LAMMPS", setting="e", cpu_s=9.0, error=3e-3)]
    at = {(r["method"], r["error"]): r for r in at_equal_error(rows, errors=(1e-4, 1e-6))}
    assert at["srkn6b", 1e-4]["cpu_s"] == pytest.approx((0.05 * 0.1) ** 0.5)
    assert at["scipy-DOP853", 1e-4]["ratio_to_srkn6b"] == pytest.approx(2.0 / (0.05 * 0.1) ** 0.5)
    assert at["srkn6b", 1e-6]["cpu_s"] is None  # no run that accurate: nothing extrapolated
    assert at["LAMMPS", 1e-4]["cpu_s"] is None and at["LAMMPS", 1e-4]["ratio_to_srkn6b"] is None


@pytest.mark.parametrize("argv", [["analyze", "nosuch.isf", "--gauge-distance", "43 mm"],
                                  ["import", "nosuch.isf", "--into", "a.h5"]])
def test_a_missing_file_is_one_line_and_exit_2(tmp_path, monkeypatch, capsys, argv):
    monkeypatch.chdir(tmp_path)
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "nosuch.isf" in err[0] and "Traceback" not in err[0]


@pytest.mark.parametrize("argv,message", [
    (["mc", "ptfe52_magnetic", "--shots", "4", "--seed", "-1", "--vary", "striker.velocity=normal(0.89 m/s, 0.01 m/s)",
      "--out", "s"], "argument --seed: '-1': a whole number from 0 to 9223372036854775807"),
    (["sweep", "ptfe52_magnetic", "--seed", "-1", "--vary", "striker.velocity=1:2:2"], "argument --seed: '-1'"),
    (["shot", "ptfe52_magnetic", "--seed", str(2**63), "--out", "a.h5"], f"argument --seed: '{2**63}'"),
    (["mc", "ptfe52_magnetic", "--shots", "4", "--accuracy", "-1", "--vary",
      "striker.velocity=normal(0.89 m/s, 0.01 m/s)", "--out", "s"], "--accuracy = -1.0: relative accuracy target"),
    (["mc", "ptfe52_magnetic", "--shots", "4", "--accuracy", "0", "--vary",
      "striker.velocity=normal(0.89 m/s, 0.01 m/s)", "--out", "s"], "--accuracy = 0.0: relative accuracy target"),
    (["shot"], "the following arguments are required: scene"),
])
def test_bad_arguments_are_one_line_and_exit_2(tmp_path, monkeypatch, capsys, argv, message):
    monkeypatch.chdir(tmp_path)
    try:
        code = main(argv)
    except SystemExit as exc:  # argparse's own checks
        code = exc.code
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and message in err[0], err
    assert not (tmp_path / "s").exists() and not (tmp_path / "a.h5").exists()  # nothing was run


def _bad_files(tmp_path, realdata):
    import h5py

    with h5py.File(tmp_path / "foreign.h5", "w") as f:
        f["x"] = [1, 2, 3]
    (tmp_path / "binary.toml").write_bytes(bytes(range(256)))
    isf = (realdata / "tek_16bit_dpo.isf").read_bytes()
    (tmp_path / "xincr0.isf").write_bytes(isf.replace(b"XINCR 400.0000E-12", b"XINCR 0.0000E-12 "))


@pytest.mark.parametrize("argv,message", [
    (["import", "{real}", "--into", "foreign.h5"], "foreign.h5: not a rig archive"),
    (["shot", "binary.toml"], "not a text (TOML) scene file"),
    (["analyze", "xincr0.isf", "--gauge-distance", "43 mm"], "XINCR = 0.0: the sample interval must be"),
])
def test_bad_files_are_one_line_and_exit_2(tmp_path, monkeypatch, capsys, realdata, argv, message):
    _bad_files(tmp_path, realdata)
    monkeypatch.chdir(tmp_path)
    argv = [a.replace("{real}", str(realdata / "tek_16bit_dpo.isf")) for a in argv]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and message in err[0], err


def test_verify_of_a_foreign_hdf5_file_says_so(tmp_path, capsys, realdata):
    _bad_files(tmp_path, realdata)
    assert main(["verify", str(tmp_path / "foreign.h5"), "--json"]) == 1
    assert "not a rig archive" in json.loads(capsys.readouterr().out)["bad"][0]["reason"]


@pytest.mark.parametrize("flag,value,message", [
    ("--gauge-distance", "4 kg", "argument --gauge-distance: '4 kg': expected a quantity convertible to m"),
    ("--sensitivity", "0.05 V", "argument --sensitivity: '0.05 V': expected a quantity convertible to V/N"),
])
def test_analysis_flags_take_units_and_name_a_wrong_one(capsys, realdata, flag, value, message):
    argv = ["analyze", str(realdata / "tek_8bit_two_records.isf"), "--gauge-distance", "43 mm", flag, value]
    with pytest.raises(SystemExit) as exc:
        main(argv)
    err = capsys.readouterr().err.strip().splitlines()
    assert exc.value.code == 2 and len(err) == 1 and message in err[0], err


def test_sensitivity_with_its_unit_equals_the_plain_number(capsys, realdata):
    files = [str(realdata / "tek_8bit_two_records.isf"), "--gauge-distance", "43 mm", "--json"]
    runs = []
    for sensitivity in ("0.05 V/N", "0.05"):
        code = main(["analyze", *files, "--sensitivity", sensitivity])
        runs.append((code, json.loads(capsys.readouterr().out)))
    with_unit, plain = runs
    assert with_unit == plain
    assert with_unit[0] == 1  # its second record is an envelope: refused, with the reason, exit 1


def test_work_precision_ratios_are_medians_of_interleaved_rounds():
    # round 2 ran on a machine twice as slow for every method: the ratios do not see it; a
    # method timed alone in a slow minute (round 3, DOP853 only) moves one ratio of three
    def rows(ours, theirs):
        return [dict(scenario="s", method="srkn6b", setting="a", cpu_s=ours, error=1e-3, ns_per_bead_eval=1.0),
                dict(scenario="s", method="srkn6b", setting="b", cpu_s=2 * ours, error=1e-5, ns_per_bead_eval=1.0),
                dict(scenario="s", method="numba-DOP853", setting="c", cpu_s=theirs, error=1e-3, ns_per_bead_eval=None),
                dict(scenario="s", method="numba-DOP853", setting="d", cpu_s=2 * theirs, error=1e-5,
                     ns_per_bead_eval=None)]
    per_round = [rows(0.1, 0.5), rows(0.2, 1.0), rows(0.1, 1.5)]
    at = {(r["method"], r["error"]): r for r in equal_error_rounds(per_round)}
    assert at["numba-DOP853", 1e-4]["ratio_to_srkn6b"] == pytest.approx(5.0)
    assert at["numba-DOP853", 1e-4]["rounds"] == 3
    med = median_rows(per_round)
    assert [r["cpu_s"] for r in med] == pytest.approx([0.1, 0.2, 1.0, 2.0])
    assert med[0]["cpu_rounds_s"] == pytest.approx([0.1, 0.2, 0.1]) and med[0]["ns_per_bead_eval"] == 1.0


def test_interleaved_rounds_alternate_their_order():
    done = []
    runs = [(name, lambda name=name: done.append(name) or {"name": name}) for name in "abc"]
    per_round = interleaved(runs, 3)
    assert done == list("abccbaabc")  # a drift within a round falls on the first and the last alike
    assert all([r["name"] for r in rows] == list("abc") for rows in per_round)


def test_an_interrupted_sweep_says_what_it_kept(tmp_path, monkeypatch, capsys):
    """Ctrl-C during a sweep: one line saying how many points were fired and where their
    shots are, not a traceback."""
    import rig.study.sweep as sweep

    def interrupted(scene, vary, overrides, seed, progress, archive):
        progress()
        progress()
        raise KeyboardInterrupt

    monkeypatch.setattr(sweep, "run_sweep", interrupted)
    out = tmp_path / "s.h5"
    argv = ["sweep", "ptfe20_gravity", "--vary", "striker.velocity=0.3:1.5:5", "--out", str(out), "--quiet"]
    assert main(argv) == 130
    err = capsys.readouterr().err.strip()
    assert err == f"rig sweep: error: interrupted after 2 of 5 points: those points' shots are in {out}"


def test_any_interrupted_command_is_one_line_and_exit_130(monkeypatch, capsys):
    import rig.cli.tools as tools

    def interrupted(args):
        raise KeyboardInterrupt

    monkeypatch.setattr(tools, "cmd_theory", interrupted)
    assert main(["theory", "--f0", "1"]) == 130
    assert capsys.readouterr().err.strip() == "rig theory: error: interrupted"


@pytest.mark.parametrize("typed,shown", [("fit1/", "fit1/"), ("fit1//", "fit1/"), ("fit1", "fit1/"),
                                         ("a/./b/", "a/b/")])
def test_a_printed_folder_has_one_trailing_separator(typed, shown):
    from rig.cli.common import folder_shown

    assert folder_shown(typed) == shown.replace("/", __import__("os").sep)


def test_an_archive_or_export_path_of_the_wrong_kind_is_named_before_the_shot(tmp_path, capsys, monkeypatch):
    """--out DIR had said "not an HDF5 file" after solving, --export FILE "File exists"."""
    import rig.solver.control

    def trap(*a, **k):
        raise AssertionError("solved before refusing the output path")

    monkeypatch.setattr(rig.solver.control, "integrate_one", trap)
    a_file = tmp_path / "notes.txt"
    a_file.write_text("x")
    for argv, words in ((["shot", "ptfe52_magnetic", "--out", str(tmp_path)], "--out"),
                        (["sweep", "ptfe52_magnetic", "--vary", "striker.velocity=0.3:1:2", "--out", str(tmp_path)],
                         "--out"),
                        (["shot", "ptfe52_magnetic", "--export", str(a_file)], "--export")):
        assert main(argv) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and words in err[0], err
        assert ("is a directory" if words == "--out" else "is a file, not a folder") in err[0], err
    assert main(["ls", str(tmp_path)]) == 2
    assert "is a directory" in capsys.readouterr().err
