"""The virtual shot: published scenes, reproducibility, recorded sizes, exported files."""
import json
from pathlib import Path

import numpy as np
import pytest

from rig.cli import main
from rig.experiment.scene import PUBLISHED_SCENES
from rig.experiment.shot import Rig
from rig.solver.problem import ChainProblem

PUBLISHED = ["ptfe52_gravity", "ptfe52_magnetic", "ptfe52_magnetic_4p25", "ptfe20_gravity",
             "steel21_gravity", "steel21_magnetic"]


@pytest.mark.parametrize("name", PUBLISHED)
def test_every_published_scene_fires_cleanly(name):
    assert (PUBLISHED_SCENES / "daraio2006" / f"{name}.toml").is_file()
    shot = Rig.from_scene(name).fire(seed=11)
    assert shot.scope.triggered
    assert set(shot.scope.waveforms) == {"CH1", "CH2", "CH3"}
    for w in shot.scope.waveforms.values():
        assert not w.overrange
        assert np.ptp(w.codes.astype(int)) > 3 * 25  # the pulses fill several divisions
    assert shot.solver.momentum_error < 1e-10


def test_same_seed_bit_identical_other_seed_different():
    rig = Rig.from_scene("ptfe52_magnetic")
    a, b = rig.fire(seed=5), Rig.from_scene("ptfe52_magnetic").fire(seed=5)
    c = rig.fire(seed=6)
    for ch in a.scope.waveforms:
        assert np.array_equal(a.scope[ch].codes, b.scope[ch].codes)
        assert a.scope[ch].preamble == b.scope[ch].preamble
    assert a.draws == b.draws
    assert not np.array_equal(a.scope["CH1"].codes, c.scope["CH1"].codes)


def test_only_the_instruments_contacts_are_recorded():
    rig = Rig.from_scene("ptfe52_magnetic")
    sol = rig.solution()
    # three connected instruments: the two contacts of each gauge bead and the wall contact
    assert sorted(sol.forces) == ["contact20", "contact21", "contact29", "contact30", "wall"]
    n = sol.time.size
    assert sol.recorded_bytes == 5 * n * 8
    whole_chain = (rig.chain.n_beads + 1) * n * 8
    assert sol.recorded_bytes < whole_chain / 10
    assert sol.frames is None


def test_no_magnet_no_magnet_term():
    gravity = ChainProblem.from_chain(Rig.from_scene("ptfe52_gravity").chain)
    magnetic = ChainProblem.from_chain(Rig.from_scene("ptfe52_magnetic").chain)
    assert gravity.sched_t.size == 0 and magnetic.sched_t.size == 0  # constant: no per-step term
    assert gravity.bias[1] == pytest.approx(9.80665)  # the magnetic bead feels gravity alone
    assert magnetic.bias[1] == pytest.approx(9.80665 + 2.38 / 0.5e-3)


def test_overrides_with_dotted_keys():
    rig = Rig.from_scene("ptfe52_magnetic", ["striker.velocity=1.2", "magnet.force=4.25"])
    assert rig.striker.velocity == 1.2 and rig.chain.top_force == 4.25
    assert Rig.from_scene("ptfe52_magnetic", ["striker.velocity=120 cm/s"]).striker.velocity == 1.2


def test_truth_holds_gauge_forces_and_positions():
    shot = Rig.from_scene("ptfe52_magnetic").fire(seed=1)
    up, low = shot.truth.gauges["upper"], shot.truth.gauges["lower"]
    assert (up.bead, low.bead) == (20, 29)  # chain index: the magnetic bead is 0
    d0 = Rig.from_scene("ptfe52_magnetic").chain.static_overlaps()
    # nine diameters less the nine static overlaps between them: 42.7 mm
    assert low.position_m - up.position_m == pytest.approx(9 * 4.76e-3 - d0[21:30].sum(), rel=1e-12)
    assert np.allclose(up.average_force, 0.5 * (up.contact_above + up.contact_below))
    assert up.average_force[0] == pytest.approx(0.5 * (up.static_above_N + up.static_below_N), rel=1e-12)


def test_isf_and_csv_round_trip_through_rigolwfm(tmp_path):
    rigolwfm = pytest.importorskip("RigolWFM.wfm")
    rigolwfm_isf = pytest.importorskip("RigolWFM.isf")
    assert main(["shot", "ptfe52_magnetic", "--seed", "3", "--export", str(tmp_path), "--format", "isf"]) == 0
    assert main(["shot", "ptfe52_magnetic", "--seed", "3", "--export", str(tmp_path), "--format", "csv"]) == 0
    shot = Rig.from_scene("ptfe52_magnetic").fire(seed=3)
    for ch in ("CH1", "CH2", "CH3"):  # the CSV export: one file per channel, as 4/5/6 Series scopes write
        csv = tmp_path / f"ptfe52_magnetic_seed3_{ch}.csv"
        table = np.loadtxt(csv, delimiter=",", skiprows=_header_rows(csv))
        ours = shot.scope[ch]
        theirs = rigolwfm.Wfm.from_file(str(tmp_path / f"ptfe52_magnetic_seed3_{ch}.isf"), "ISF").channels[0]
        assert len(theirs.volts) == ours.preamble.points
        # RigolWFM scales in float32: agreement to 1e-4 of a code (one code is y_multiplier)
        tol = 1e-4 * ours.preamble.y_multiplier
        assert np.allclose(theirs.volts, ours.volts(), rtol=0, atol=tol)
        assert np.allclose(theirs.times, ours.time(), rtol=0, atol=1e-12)
        assert np.allclose(table[:, 1], theirs.volts, rtol=0, atol=tol)  # the CSV agrees
        assert np.allclose(table[:, 0], ours.time(), rtol=0, atol=1e-6 * ours.preamble.x_increment)
        isf = rigolwfm_isf.from_file(str(tmp_path / f"ptfe52_magnetic_seed3_{ch}.isf"))
        assert isf.header.trace_label.startswith(f"{ch}, ")  # the WFID names the channel first


def _header_rows(path: Path) -> int:
    lines = path.read_text().splitlines()
    return next(i for i, line in enumerate(lines) if line.startswith("TIME,")) + 1


def test_shot_json_keys(capsys):
    assert main(["shot", "steel21_magnetic", "--seed", "2", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["scenario"] == "steel21_magnetic" and out["seed"] == 2
    assert set(out["solver"]) == {"method", "dt_s", "steps", "wall_s", "energy_error", "momentum_error",
                                  "accuracy", "error_estimate", "bodies_stepped"}
    assert out["solver"]["error_estimate"] <= out["solver"]["accuracy"]  # the contract, as the shot reports it
    assert 1 <= out["solver"]["bodies_stepped"] <= 1 + 21 + 1 + 1  # striker, beads, magnetic bead, wall at most
    assert set(out["channels"]) == {"CH1", "CH2", "CH3"}
    assert out["channels"]["CH3"]["connected"] == "wall_sensor"


def test_no_trigger_is_reported(capsys):
    assert main(["shot", "ptfe52_magnetic", "--seed", "1", "--set", "scope.trigger.level=5", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["triggered"] is False and "no rising crossing" in out["no_trigger_reason"]


@pytest.mark.parametrize("override,field", [
    ("scope.channels.CH1.volts_per_div=0", "volts_per_div"),
    ("scope.record_length=0", "record_length"),
    ("gauges.upper.bead=60", "gauges.upper.bead"),
    ("scope.trigger.source=CH4", "scope.trigger.source"),
    ("holder.bore=4 mm", "diameter"),
    ("chain.colour=red", "chain.colour"),
    ("gauges.upper.channel=CH3", "already taken"),
])
def test_bad_scene_settings_name_the_field(override, field):
    with pytest.raises(ValueError, match=field):
        Rig.from_scene("ptfe52_magnetic", [override])


def test_trigger_on_an_unconnected_channel(tmp_path):
    with pytest.raises(ValueError, match="unconnected channel"):
        Rig.from_scene("ptfe52_magnetic", ["scope.channels.CH4.volts_per_div=0.1",
                                           "scope.trigger.source=CH4"])


def test_quantity_without_unit_in_a_scene_file(tmp_path):
    text = (PUBLISHED_SCENES / "daraio2006" / "ptfe52_magnetic.toml").read_text()
    bad = tmp_path / "bad.toml"
    bad.write_text(text.replace('diameter = "4.76 mm"', "diameter = 4.76"))
    with pytest.raises(ValueError, match=r"chain\.diameter.*unit is required"):
        Rig.from_scene(bad)


def test_a_scene_with_the_wall_sensor_alone(tmp_path, capsys):
    text = (PUBLISHED_SCENES / "daraio2006" / "steel21_gravity.toml").read_text()
    head, _, rest = text.partition("[gauges.upper]")
    scope = rest[rest.index("[scope]"):]
    scene = tmp_path / "wall_only.toml"
    scene.write_text(head + scope.replace('source = "CH1"', 'source = "CH3"'))
    assert main(["shot", str(scene), "--seed", "1", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["triggered"] and out["truth"] is None and out["channels"]["CH3"]["connected"] == "wall_sensor"
    assert main(["shot", str(scene), "--seed", "1"]) == 0
    assert "two gauge beads" in capsys.readouterr().out


def test_a_rig_like_another_takes_over_only_the_parts_of_shared_tables():
    # studies build each shot's rig "like" a template: parts of the very same scene tables
    # are taken over, the others built anew, and the shot is the one a fresh rig fires
    from rig.experiment import scene as scene_io

    scene = scene_io.load("ptfe52_magnetic")
    template = Rig(scene)
    v = dict(scene.values)
    v["striker"] = {**scene.values["striker"], "velocity": 0.95}
    masses = [0.1226e-3 * (1 + 0.001 * k) for k in range(52)]
    shot_scene = scene.with_values(v)
    alike, fresh = Rig(shot_scene, bead_masses=masses, like=template), Rig(shot_scene, bead_masses=masses)
    assert alike.scope is template.scope and alike.gauges is template.gauges
    assert alike.striker is not template.striker and alike.striker.velocity == 0.95
    a, b = alike.fire(seed=5, truth=False), fresh.fire(seed=5, truth=False)
    for ch, w in b.scope.waveforms.items():
        assert np.array_equal(a.scope.waveforms[ch].codes, w.codes)
