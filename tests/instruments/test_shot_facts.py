"""The archive's shot facts: a declared, versioned structure that both sides check."""
import json
import subprocess
import sys
from dataclasses import replace

import h5py
import pytest
from test_archive import entry
from test_archive_parts import _layout3

from instruments.archive import Archive
from instruments.archive.facts import FACTS_VERSION, GaugeFact, ShotFacts
from instruments.errors import InstrumentError

FACTS = ShotFacts(1e-7, {"upper": GaugeFact(20, "CH1", 0.0901, 0.95, 0.96),
                         "lower": GaugeFact(29, "CH2", 0.1328, 0.96, 0.97)},
                  {"speed_m_per_s": 228.3}, 229.0, {"upper": {"gain": 1.01, "misalignment_m": 1e-4}}, 3.9e-4,
                  {"method": "srkn6b"}, ("striker.velocity=1.2",))


def test_round_trip_through_json():
    stored = json.loads(json.dumps(FACTS.to_dict()))
    assert stored["version"] == FACTS_VERSION
    assert ShotFacts.from_dict(stored) == FACTS
    study = replace(FACTS, study_shot=19, study="abc123")  # what a Monte Carlo study adds
    assert ShotFacts.from_dict(json.loads(json.dumps(study.to_dict()))) == study


def test_the_json_keys_are_those_older_archives_hold():
    assert set(FACTS.to_dict()) == {"sample_interval_s", "gauges", "analysis", "wave_speed_m_per_s", "draws",
                                    "trigger_time_after_impact_s", "solver", "overrides", "study_shot", "study",
                                    "version"}
    assert set(FACTS.to_dict()["gauges"]["upper"]) == {"bead", "channel", "position_m", "static_above_N",
                                                      "static_below_N"}


@pytest.mark.parametrize("change,message", [
    (lambda d: d.update(colour="red"), "facts.colour: unknown key"),
    (lambda d: d.pop("gauges"), "facts.gauges: missing"),
    (lambda d: d.update(version=99), "facts.version = 99: this version reads version 1"),
    (lambda d: d.update(sample_interval_s="fast"), "facts.sample_interval_s = 'fast': expected int or float"),
    (lambda d: d.update(version="1"), "facts.version = '1': this version reads version 1"),
    (lambda d: d.update(version=True), "facts.version = True: this version reads version 1"),
    (lambda d: d.update(sample_interval_s=None), "facts.sample_interval_s = None: expected int or float"),
    (lambda d: d.update(draws=[]), r"facts.draws = \[\]: expected dict"),
    (lambda d: d.update(analysis="none"), "facts.analysis = 'none': expected dict or null"),
    (lambda d: d.update(study=7), "facts.study = 7: expected str or null"),
    (lambda d: d.update(overrides=["a=1", 2]), r"facts.overrides\[1\] = 2: expected str"),
    (lambda d: d["gauges"]["upper"].pop("channel"), "facts.gauges.upper.channel: missing"),
    (lambda d: d["gauges"]["upper"].update(colour="red"), r"facts.gauges.upper.colour: unknown key \(known: bead"),
    (lambda d: d["gauges"].update(upper=3), "facts.gauges.upper = 3: expected a table of bead, channel"),
    (lambda d: d["gauges"]["upper"].update(bead=20.5), "facts.gauges.upper.bead = 20.5: expected int"),
    (lambda d: d.update(study_shot=True), "facts.study_shot = True: expected int or null"),
    (lambda d: d["gauges"]["lower"].update(position_m="far"), "facts.gauges.lower.position_m = 'far'"),
])
def test_bad_facts_are_refused_naming_the_field(change, message):
    d = json.loads(json.dumps(FACTS.to_dict()))
    change(d)
    with pytest.raises(InstrumentError, match=message):
        ShotFacts.from_dict(d)


@pytest.mark.parametrize("layout", [3, 4])
def test_unversioned_facts_of_older_archives_still_read(tmp_path, layout):
    a, e = _archive(tmp_path, layout), entry(3)
    (shot,) = a.append([e])
    old = e.facts.to_dict()
    del old["version"], old["study_shot"], old["study"], old["overrides"]
    with h5py.File(a.path, "r+") as f:  # as an archive written before the version was recorded
        _rewrite_facts(f, json.dumps(old), shot)
    assert Archive(a.path).read(shot, verify=False).facts == e.facts


@pytest.mark.parametrize("layout,damaged", [(3, "truth/facts"), (4, "attribute @metadata")])
def test_damaged_facts_name_the_shot_and_the_field(tmp_path, layout, damaged):
    a = _archive(tmp_path, layout)
    (shot,) = a.append([entry(4)])
    with h5py.File(a.path, "r+") as f:
        d = _facts(f, shot)
        d["gauges"]["upper"]["position_m"] = "far"
        d["unexpected"] = 1
        _rewrite_facts(f, json.dumps(d), shot)
    with pytest.raises(InstrumentError, match=f"shot {shot}: facts.unexpected: unknown key"):
        Archive(a.path).read(shot, verify=False)  # what a reader that skips the checksums still refuses
    with pytest.raises(InstrumentError, match=f"shot {shot}: {damaged}: damaged"):
        Archive(a.path).read(shot)


@pytest.mark.parametrize("layout", [3, 4])
def test_unversioned_facts_with_a_study_s_keys_still_read(tmp_path, layout):
    a, e = _archive(tmp_path, layout), entry(5)
    (shot,) = a.append([e])
    old = e.facts.to_dict()
    del old["version"]
    old.update(study_shot=7, study="d1g35t")
    with h5py.File(a.path, "r+") as f:
        _rewrite_facts(f, json.dumps(old), shot)
    assert Archive(a.path).read(shot, verify=False).facts == replace(e.facts, study_shot=7, study="d1g35t")


@pytest.mark.parametrize("facts,message", [
    ({"sample_interval_s": 1e-7}, "shot 3: facts = dict: expected ShotFacts"),
    (replace(FACTS, version=2), "shot 3: facts.version = 2: this version reads version 1"),
    (replace(FACTS, sample_interval_s=object()), "shot 3: facts.sample_interval_s = '<object"),
    (replace(FACTS, gauges={"upper": GaugeFact(20.5, "CH1", 0.09, 0.9, 0.9)}),
     "shot 3: facts.gauges.upper.bead = 20.5: expected int"),
])
def test_the_archive_refuses_to_write_facts_it_would_refuse_to_read(tmp_path, facts, message):
    path = tmp_path / "w.h5"
    a = Archive(path)
    a.append([entry(1)])
    with pytest.raises(InstrumentError, match=message):
        a.append([entry(2), replace(entry(3), facts=facts)])
    assert a.ids() == [1] and a.verify() == {"shots": 1, "ok": 1, "bad": []}  # all or nothing


def test_a_shot_without_facts_reads_none(tmp_path):
    path = tmp_path / "n.h5"
    Archive(path).append([replace(entry(1), facts=None), entry(2, truth=False)])
    assert Archive(path).read(1).facts is None and Archive(path).read(1).truth is not None
    assert Archive(path).read(2).facts is None and Archive(path).read(2).truth is None


def _archive(tmp_path, layout: int) -> Archive:
    """A new archive (layout 4), or a copy of a layout-3 one, which is appended to in layout 3."""
    return _layout3(tmp_path) if layout == 3 else Archive(tmp_path / "new.h5")


def _facts(f, shot: int) -> dict:
    """Shot ``shot``'s stored facts: layout 4 keeps them in the shot's metadata attribute,
    older layouts in truth/facts."""
    g = f[f"shot_{shot:06d}"]
    return json.loads(g.attrs["metadata"])["facts"] if "metadata" in g.attrs else json.loads(g["truth/facts"][()])


def _rewrite_facts(f, text: str, shot: int):
    g = f[f"shot_{shot:06d}"]
    if "metadata" in g.attrs:
        g.attrs["metadata"] = json.dumps(json.loads(g.attrs["metadata"]) | {"facts": json.loads(text)})
    else:
        del g["truth/facts"]
        g["truth"].create_dataset("facts", data=text)


def test_facts_and_entries_need_no_h5py():
    code = ("import sys, instruments.archive.facts, instruments.archive; "
            "print('h5py' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert out.stdout.strip() == "False", out.stderr
