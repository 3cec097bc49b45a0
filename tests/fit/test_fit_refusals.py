"""rig fit refuses what the data cannot say, and flags what it cannot vouch for: a
parameter the data do not see, fewer data than parameters, the same data twice, bounds the
physics refuses, a model the chi2 rules out, a value at its bound. A refused fit (exit 2)
leaves its folder as it was; a fit that runs but cannot stand for the scene (exit 1) writes
no fitted scene and removes an earlier one."""
import json
import math
import shutil

import numpy as np
import pytest

from rig.cli import main
from rig.errors import RigError
from rig.fit.data import read_points
from rig.fit.evaluate import curves

SCENE = "ptfe20_gravity"
E = "chain.youngs_modulus=0.5 GPa:3 GPa"
EARLIER = "# an earlier fit's scene\n"
HEAD = "F_d [N],F_d_sd [N],V_s [m/s],V_s_sd [m/s]\n"
HALF = ["solver.duration=1.5e-3", "scope.record_length=3125"]  # the scene's first 1.25 ms of record (of 2.5 ms)


@pytest.fixture(scope="module")
def curve():
    """The model's own curve at E = 1.1 GPa, three striker velocities."""
    (c,) = curves(SCENE, [["chain.youngs_modulus=1.1e9"]], [0.5, 0.9, 1.6])
    return c


def _points(tmp_path, rows, name="points.csv"):
    path = tmp_path / name
    path.write_text(HEAD + "".join(f"{F},{0.1 * F},{V},{0.03 * V}\n" for F, V in rows))
    return path


def _fit(tmp_path, capsys, data, *params, stale=True):
    """(exit code, stderr, out folder) of rig fit with a fitted.toml of an earlier fit in place."""
    out = tmp_path / "fit"
    out.mkdir(exist_ok=True)
    if stale:
        (out / "fitted.toml").write_text(EARLIER)
    argv = ["fit", SCENE, *data, "--out", str(out), "--quiet"]
    for p in params:
        argv += ["--param", p]
    code = main(argv)
    return code, capsys.readouterr().err.strip(), out


def _refused(out):
    """Nothing written: the earlier fit's scene is still there, as it was, and nothing else
    (no evaluations/ cache of the refused run)."""
    assert (out / "fitted.toml").read_text() == EARLIER and not (out / "fit.json").exists()
    assert sorted(p.name for p in out.rglob("*")) == ["fitted.toml"]


def _one_line(err, *words):
    assert len(err.splitlines()) == 1 and "Traceback" not in err, err
    for w in words:
        assert w in err, (w, err)


def test_a_parameter_the_data_do_not_see_is_refused_by_name(tmp_path, capsys, curve):
    """The points set the striker's velocity themselves: its Jacobian column is zero, and
    its sd would come out 0 from the pseudo-inverse (the old '0.89 +- 0')."""
    pts = _points(tmp_path, zip(curve.force, curve.speed))
    code, err, out = _fit(tmp_path, capsys, ["--points", str(pts)], E, "striker.velocity=0.5 m/s:1.5 m/s")
    assert code == 2
    _one_line(err, "--param = 'striker.velocity'", "the data do not see it")
    _refused(out)


def test_fewer_data_than_parameters_is_refused_before_any_solve(tmp_path, capsys):
    pts = _points(tmp_path, [(1.0, 100.0)])
    code, err, out = _fit(tmp_path, capsys, ["--points", str(pts)], E, "chain.contact_exponent=1.2:2")
    assert code == 2
    _one_line(err, "1 data for 2 --param keys")
    assert not (out / "evaluations").exists()  # nothing solved
    _refused(out)


def test_a_refused_fit_into_a_new_folder_leaves_no_folder(tmp_path, capsys, curve):
    """Refused before any solve (too few data) and after its evaluations (a parameter the
    data do not see): the --out folder that did not exist does not exist after."""
    out = tmp_path / "new" / "fit"
    few = _points(tmp_path, [(1.0, 100.0)], "few.csv")
    unseen = _points(tmp_path, zip(curve.force, curve.speed))
    for data, param in ((few, "chain.contact_exponent=1.2:2"), (unseen, "striker.velocity=0.5 m/s:1.5 m/s")):
        assert main(["fit", SCENE, "--points", str(data), "--param", E, "--param", param, "--out", str(out),
                     "--quiet"]) == 2
        capsys.readouterr()
        assert not out.exists() and not out.parent.exists()


def test_the_same_point_twice_is_refused_naming_both_lines(tmp_path):
    path = tmp_path / "twice.csv"
    path.write_text(HEAD + "1.0,0.1,100,3\n2.0,0.2,120,3.6\n1.0,0.1,100,3\n")
    with pytest.raises(RigError, match=r"line 4 = '1.0,0.1,100,3': repeats line 2"):
        read_points(path)
    path.write_text(HEAD + "1.0,0.1,100,3\n1.0,0.1,100,4\n")  # the same point with another sd: two measurements
    assert read_points(path).n == 2


def test_the_same_record_twice_is_refused(tmp_path, capsys):
    from instruments.formats.tek_csv import write_csv
    from rig.experiment.shot import Rig

    path = write_csv(Rig.from_scene(SCENE).fire(seed=3).scope.waveforms, tmp_path, "shot")[0]  # one file a channel
    copy = tmp_path / "copy.csv"
    shutil.copy(path, copy)
    for files in ([path, path], [path, copy]):
        code, err, out = _fit(tmp_path, capsys, ["--records", *map(str, files)], E)
        assert code == 2
        _one_line(err, f"--records = '{files[1]}'", f"the same data as {files[0]}")
        _refused(out)


@pytest.mark.parametrize("bounds,words", [
    ("-1 GPa:3 GPa", ["--param chain.youngs_modulus LO = '-1e+09 Pa'", "the scene refuses it", "must be > 0"]),
    ("1e-300 Pa:1e300 Pa", ["--param chain.youngs_modulus LO = '1e-300 Pa'", "no time step"]),
    ("0.5 GPa:1e300 Pa", ["--param chain.youngs_modulus HI = '1e+300 Pa'", "no time step"]),
    ("1 Pa:3 Pa", ["at the fit's start values (chain.youngs_modulus = 2 Pa)"]),
])
def test_bounds_outside_physics_are_one_line_naming_key_and_value(tmp_path, capsys, curve, bounds, words):
    pts = _points(tmp_path, zip(curve.force, curve.speed))
    code, err, out = _fit(tmp_path, capsys, ["--points", str(pts)], f"chain.youngs_modulus={bounds}")
    assert code == 2
    _one_line(err, *words)
    _refused(out)


def test_a_model_the_chi2_rules_out_is_flagged_with_widened_intervals_and_no_scene(tmp_path, capsys, curve):
    """Speeds that grow 4x slower with the force than any modulus lets the model's, at 0.2%:
    the optimiser converges, but the fit is not plausible; its sds carry sqrt(chi2/dof)."""
    speeds = curve.speed[0] * (curve.force / curve.force[0]) ** (
        0.25 * np.log(curve.speed[-1] / curve.speed[0]) / np.log(curve.force[-1] / curve.force[0]))
    path = tmp_path / "slow.csv"
    path.write_text(HEAD + "".join(f"{F},{0.01 * F},{V},{0.002 * V}\n" for F, V in zip(curve.force, speeds)))
    code, err, out = _fit(tmp_path, capsys, ["--points", str(path)], E)
    block = json.loads((out / "fit.json").read_text())
    assert code == 1 and "the fit converged, but the model does not describe the data" in err
    assert block["converged"] is True and block["plausible"] is False and block["chi2_reduced"] > 10
    assert block["interval_scale"] == pytest.approx(math.sqrt(block["chi2_reduced"]))
    assert any(w.startswith("the model does not describe the data") for w in block["warnings"])
    assert block["fitted_scene"] is None and not (out / "fitted.toml").exists()


def test_a_value_at_its_bound_is_flagged_naming_the_bound(tmp_path, capsys, curve):
    """The truth (1.1 GPa) below the bounds: the fit stops at the lower bound and says so."""
    pts = _points(tmp_path, zip(curve.force, curve.speed))
    code, err, out = _fit(tmp_path, capsys, ["--points", str(pts)], "chain.youngs_modulus=1.5 GPa:3 GPa")
    block = json.loads((out / "fit.json").read_text())
    assert block["at_bound"] == ["chain.youngs_modulus"]
    assert "chain.youngs_modulus = 1.5e+09 Pa is at its lower bound 1.5e+09 Pa" in " ".join(block["warnings"])
    # as the fitting tutorial says: such a fit writes no fitted scene and exits 1 (it had written one, exit 0)
    assert code == 1 and "chain.youngs_modulus ended at a bound of --param" in err
    assert block["fitted_scene"] is None and not (out / "fitted.toml").exists()


def test_real_records_that_are_no_impact_are_refused_or_flagged(tmp_path, capsys, realdata):
    """Real single-channel records read as the upper gauge; the old fits reported E with
    an sd of 0 or passing its bounds, wrote a fitted scene and exited 0. An accelerometer
    record: at the result E's sd is 100 times its bounds' span: undetermined. A TDS2001C
    record: E is determined, but chi2/dof ~ 760 rules the model out."""
    code, err, out = _fit(tmp_path, capsys, ["--records", str(realdata / "accel_TEK00000.CSV")], E)
    block = json.loads((out / "fit.json").read_text())
    assert code == 1 and "the data do not determine chain.youngs_modulus" in err
    assert block["undetermined"] == ["chain.youngs_modulus"] and block["fitted_scene"] is None
    assert block["parameters"]["chain.youngs_modulus"]["std"] > 2.5e9  # not the old sd of 0
    assert not (out / "fitted.toml").exists()
    code, err, out = _fit(tmp_path, capsys, ["--records", str(realdata / "pchem_TDS2001C_F0000CH1.CSV")], E)
    block = json.loads((out / "fit.json").read_text())
    assert code == 1 and "the model does not describe the data" in err
    assert block["plausible"] is False and block["chi2_reduced"] > 100 and block["fitted_scene"] is None
    assert not (out / "fitted.toml").exists()


def test_the_same_shot_twice_in_the_records_is_refused():
    """Two channels with the same samples (an archive holding the same shot twice)."""
    from rig.fit.checks import check_distinct_channels
    from rig.fit.traces import Channel

    t = np.linspace(-1e-4, 1e-3, 200)
    one = Channel(0, "CH1", t, np.sin(1e4 * t), 1e-3, 0.05, 0.0)
    check_distinct_channels([one, Channel(1, "CH1", t, np.sin(1e4 * t) + 1e-3, 1e-3, 0.05, 0.0)])
    with pytest.raises(RigError, match=r"records = 'record 2 CH1': the same samples as record 1 CH1"):
        check_distinct_channels([one, Channel(1, "CH1", t, np.sin(1e4 * t), 1e-3, 0.05, 0.0)])


def test_as_many_points_as_parameters_fits_but_says_chi2_is_undefined(tmp_path, capsys, curve):
    """One point, one parameter: no degrees of freedom. chi2/dof and p are null (not NaN in
    the JSON), plausibility is not judged, and the fit says why."""
    pts = _points(tmp_path, [(curve.force[1], curve.speed[1])])
    code, err, out = _fit(tmp_path, capsys, ["--points", str(pts)], E, stale=False)
    block = json.loads((out / "fit.json").read_text())
    assert block["dof"] == 0 and block["chi2_reduced"] is None and block["p_value"] is None
    assert block["plausible"] is None and block["interval_scale"] == 1.0
    assert any("chi2/dof and p are undefined" in w for w in block["warnings"])
    lo, hi = block["parameters"]["chain.youngs_modulus"]["ci95"]
    assert lo <= 1.1e9 <= hi


@pytest.mark.parametrize("flags,words", [
    (["--set", "magnet.force=2 N"], ["--set", "magnet.force", "its column"]),
    (["--param", "magnet.force=1 N:3 N"], ["--param", "magnet.force", "cannot also be fixed"]),
])
def test_a_key_the_points_set_row_by_row_is_not_also_set_or_fitted(tmp_path, capsys, flags, words):
    """A --points column sets its key for each row, after --set: a --set of it had been
    dropped silently, and a fitted key overwritten by the column."""
    path = tmp_path / "points.csv"
    path.write_text(HEAD.rstrip("\n") + ",magnet.force [N]\n" + "2,0.2,150,4.5,2.38\n3,0.3,170,5.1,4.25\n")
    code, err, out = _fit(tmp_path, capsys, ["--points", str(path), *flags], "chain.youngs_modulus=0.4 GPa:2 GPa")
    assert code == 2
    _one_line(err, *words)
    _refused(out)


def test_an_archives_shots_are_each_modelled_with_their_own_setup(tmp_path, capsys):
    """A sweep's archive (each shot at its own striker velocity): every shot had been
    modelled at the scene's 0.89 m/s. Each is now modelled with the overrides it was fired
    with (the fitted key left to the fit), and E comes back within its interval at a chi2
    the instruments' noise explains; a shot of another scene is refused by name. The shots
    are the scene's first half (HALF: the fit models them so, from their own overrides)."""
    from instruments.archive import Archive
    from rig.experiment.entry import shot_entry
    from rig.experiment.shot import Rig

    archive = Archive(tmp_path / "sweep.h5")
    archive.append([shot_entry(Rig.from_scene("ptfe20_gravity", ["chain.youngs_modulus=1.2e9",
                                                                  f"striker.velocity={v}", *HALF]).fire(seed=s))
                    for s, v in ((1, 0.7), (2, 1.0))])
    near = "chain.youngs_modulus=1 GPa:1.5 GPa"  # (from 0.5 GPa the trace fit finds another minimum near 2.2 GPa)
    code = main(["fit", "ptfe20_gravity", "--archive", str(archive.path), "--param", near, "--out",
                 str(tmp_path / "fit"), "--quiet", "--json"])
    block = json.loads(capsys.readouterr().out)
    assert code == 0 and block["converged"], block
    lo, hi = block["parameters"]["chain.youngs_modulus"]["ci95"]
    assert lo <= 1.2e9 <= hi and block["chi2_reduced"] < 2, block
    archive.append([shot_entry(Rig.from_scene("steel21_gravity").fire(seed=1))])
    code = main(["fit", "ptfe20_gravity", "--archive", str(archive.path), "--param", near, "--out",
                 str(tmp_path / "fit2")])
    err = capsys.readouterr().err
    assert code == 2 and "shot 3 was fired with " in err and len(err.strip().splitlines()) == 1, err


def test_a_second_fit_into_a_folder_in_use_is_refused(tmp_path, capsys, curve):
    """Two rig fit into one --out had overwritten each other's files: the folder is held
    while a fit writes it, and a second is refused in one line naming the holder."""
    from instruments.files import folder_lock
    from rig.fit.run import LOCK

    pts = _points(tmp_path, zip(curve.force, curve.speed))
    out = tmp_path / "fit"
    with folder_lock(out, LOCK, "another fit"):  # a fit of another process writing there now
        code = main(["fit", "ptfe52_gravity", "--points", str(pts), "--param", E, "--out", str(out)])
    err = capsys.readouterr().err
    assert code == 2 and len(err.strip().splitlines()) == 1 and "in use by another run (pid" in err, err
    assert not (out / "fit.json").exists()
