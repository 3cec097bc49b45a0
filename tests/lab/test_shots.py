"""A scene as a virtual scope's shot source (rig/lab/shots.py): the records are the bits of
``rig shot --set ... --seed N --export`` read back from its files; refusals are one line."""
import json

import numpy as np
import pytest

from instruments.archive import Archive
from instruments.errors import InstrumentError
from instruments.formats import read_waveforms
from rig.cli import main
from rig.errors import RigError
from rig.lab.shots import RIG_KEYS, SceneShots

SCENE = "ptfe52_magnetic"
QUICK = ("solver.duration=1.5 ms", "scope.record_length=2500", "scope.sample_interval=0.4 us")  # ~1 ms record


@pytest.fixture(scope="module")
def shots():
    return SceneShots(SCENE, QUICK)


def cli_export(tmp_path, items, seed):
    """The waveforms ``rig shot SCENE --set ... --seed SEED --export DIR`` wrote, read back."""
    argv = ["shot", SCENE, "--seed", str(seed), "--export", str(tmp_path / f"seed{seed}"), "--json"]
    for item in items:
        argv += ["--set", item]
    return argv


@pytest.mark.parametrize("overrides, seed", [
    ({"scope.channels.CH1.volts_per_div": "0.1 V"}, 4),  # the scope only: the chain's solve is shared
    ({"striker.velocity": "0.7 m/s", "magnet.force": "3 N", "scope.trigger.level": "20 mV"}, 5),
])
def test_a_shot_is_the_bits_rig_shot_exports(shots, tmp_path, capsys, overrides, seed):
    shots({}, 3)  # the base scene solved first: the scope-only set takes its solution
    record = shots(overrides, seed)
    argv = cli_export(tmp_path, QUICK + tuple(f"{k}={v}" for k, v in overrides.items()), seed)
    assert main(argv) == 0
    exported = json.loads(capsys.readouterr().out)["exported"]
    files = {w.channel: w for path in exported for w in read_waveforms(path)}
    assert record.triggered and sorted(files) == sorted(record.waveforms) == ["CH1", "CH2", "CH3"]
    for ch, w in record.waveforms.items():
        f = files[ch]
        assert f.codes.dtype == w.codes.dtype and np.array_equal(f.codes, w.codes), ch
        assert f.preamble.x_increment == pytest.approx(w.preamble.x_increment, rel=1e-12)
        assert f.preamble.y_multiplier == pytest.approx(w.preamble.y_multiplier, rel=1e-12)
    assert np.ptp(record["CH1"].codes) > 20  # a pulse, not the noise floor alone
    assert shots.last.seed == seed and {f"{k}={v}" for k, v in overrides.items()} <= set(shots.last.overrides)


def test_the_overrides_change_the_record_and_the_same_call_repeats_its_bits(shots):
    base, again = shots({}, 7), shots({}, 7)
    assert all(np.array_equal(base[ch].codes, again[ch].codes) for ch in base.waveforms)
    other_seed = shots({}, 8)
    assert not np.array_equal(base["CH1"].codes, other_seed["CH1"].codes)  # the noise is the seed's
    finer = shots({"scope.channels.CH1.volts_per_div": "0.02 V"}, 7)
    assert finer["CH1"].preamble.y_multiplier == pytest.approx(base["CH1"].preamble.y_multiplier / 2.5, rel=1e-9)
    assert np.array_equal(finer["CH2"].codes, base["CH2"].codes)  # CH2 untouched, the same draws
    slower = shots({"striker.velocity": "0.5 m/s"}, 7)
    def peak(r):
        return float(r["CH1"].volts().max())
    assert peak(slower) < 0.8 * peak(base)  # F ~ v^(6/5): 0.5/0.89 gives about half the force


def test_each_override_set_builds_one_rig_and_the_cache_is_bounded():
    shots = SceneShots(SCENE, dict(item.split("=") for item in QUICK), cache=2)
    a = shots.rig({"magnet.force": "2 N"})
    assert shots.rig({"magnet.force": "2 N"}) is a
    assert shots.rig({"magnet.force": "2.0 N"}) is not a  # the text is the key, as --set reads it
    shots.rig({"magnet.force": "3 N"})
    assert shots.rig({"magnet.force": "2 N"}) is not a  # dropped: the least recently used of 3
    assert shots.rig({"solver.duration": "2 ms"}).solver.duration == pytest.approx(2e-3)  # a call's key wins


def test_every_shot_is_handed_on_and_archives_as_rig_shot_out(tmp_path):
    from rig.lab.shots import append_shot

    served = []
    shots = SceneShots(SCENE, QUICK, on_shot=served.append)
    record = shots({"magnet.force": "2 N"}, 11)
    assert [s.scope for s in served] == [record] and served[0].seed == 11
    archive = tmp_path / "served.h5"
    number = append_shot(archive, served[0])
    entry = Archive(archive).read(number)
    assert entry.seed == 11 and "magnet.force=2 N" in entry.settings["overrides"]
    assert np.array_equal(entry.record["CH2"].codes, record["CH2"].codes)


@pytest.mark.parametrize("overrides, named", [
    ({"striker.velocity": "fast"}, "striker.velocity"),
    ({"striker.velocity": "2 kg"}, "striker.velocity"),
    ({"scope.channels.CH1.volts_per_div": "-1 V"}, "volts_per_div"),
    ({"scope.nonsense": "1"}, "scope.nonsense"),
    ({"magnet.force": "1e6 N"}, "magnet.force"),
])
def test_a_refused_setting_is_one_instrument_error_line(shots, overrides, named):
    with pytest.raises(InstrumentError) as err:
        shots(overrides, 1)
    line = str(err.value)
    assert named in line and "\n" not in line and len(line) < 600


def test_validate_takes_the_rig_keys_with_units_as_scene_files(shots):
    assert shots.validate("striker.velocity", "0.9 m/s") is None
    assert shots.validate("magnet.force", "2380 mN") is None
    assert shots.validate("striker.velocity", "1.2") is None  # a plain number is in SI, as in --set
    for key, text, named in [("magnet.force", "2 kg", "magnet.force"), ("striker.velocity", "-1 m/s", "> 0"),
                             ("striker.velocity", "1,5 m/s", "striker.velocity"),
                             ("scope.record_length", "10", "striker.velocity, magnet.force"),
                             ("magnet.position", "5 cm", "one of force, position")]:  # this scene gives the force
        why = shots.validate(key, text)
        assert why is not None and named in why and "\n" not in why, (key, text, why)
    assert set(RIG_KEYS) == {"striker.velocity", "magnet.force", "magnet.position"}


def test_a_bad_scene_or_base_setting_is_refused_before_any_shot():
    with pytest.raises(RigError, match="no_such_scene"):
        SceneShots("no_such_scene")
    with pytest.raises(RigError, match="striker.speed"):
        SceneShots(SCENE, ["striker.speed=1 m/s"])


def test_shots_asked_from_many_threads_at_once_are_the_shots_asked_one_by_one(shots):
    """The servers call the source from a thread per client: the rigs built meanwhile are
    shared, never half-built, and each shot keeps its own bits."""
    from concurrent.futures import ThreadPoolExecutor

    asks = [({"magnet.force": f"{2 + k % 3 * 0.25} N", "scope.channels.CH2.volts_per_div": "0.1 V"}, 20 + k)
            for k in range(9)]
    with ThreadPoolExecutor(6) as pool:
        together = list(pool.map(lambda ask: shots(*ask), asks))
    alone = SceneShots(SCENE, QUICK)
    for (overrides, seed), record in zip(asks, together):
        one = alone(overrides, seed)
        assert all(np.array_equal(one[ch].codes, record[ch].codes) for ch in one.waveforms), seed


def test_checking_a_setting_solves_no_earlier_shot_of_the_chain(monkeypatch):
    """A scene served with a shot history (chain.previous_shots): checking a RIG: value or a
    record's size builds the rig without its history (each earlier shot is a solve); the
    shot itself has it."""
    import rig.experiment.shot as shot_module

    solved = []
    real = shot_module.after_shots
    monkeypatch.setattr(shot_module, "after_shots", lambda *a: solved.append(a[1]) or real(*a))
    shots = SceneShots(SCENE, QUICK + ("chain.contact_law=thornton", "chain.yield_force=0.8 N",
                                       "chain.previous_shots=2"))
    assert shots.validate("striker.velocity", "1.0 m/s") is None
    assert shots.record_cost({"scope.record_length": "2500"}) is None
    assert solved == []
    assert "chain.previous_shots=2" in shots.shot({}, 1).overrides and solved == [2]
