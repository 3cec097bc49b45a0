"""The archive's shot facts: a declared, versioned structure that both sides check."""
import json

import h5py
import pytest
from test_archive import entry

from instruments.archive import Archive
from instruments.errors import InstrumentError
from instruments.facts import FACTS_VERSION, GaugeFact, ShotFacts

FACTS = ShotFacts(1e-7, {"upper": GaugeFact(20, "CH1", 0.0901, 0.95, 0.96),
                         "lower": GaugeFact(29, "CH2", 0.1328, 0.96, 0.97)},
                  {"speed_m_per_s": 228.3}, 229.0, {"upper": {"gain": 1.01, "misalignment_m": 1e-4}}, 3.9e-4,
                  {"method": "srkn6b"}, ("striker.velocity=1.2",))


def test_round_trip_through_json():
    stored = json.loads(json.dumps(FACTS.to_dict()))
    assert stored["version"] == FACTS_VERSION
    assert ShotFacts.from_dict(stored) == FACTS


@pytest.mark.parametrize("change,message", [
    (lambda d: d.update(colour="red"), "facts.colour: unknown key"),
    (lambda d: d.pop("gauges"), "facts.gauges: missing"),
    (lambda d: d.update(version=99), "facts.version = 99: this version reads version 1"),
    (lambda d: d.update(sample_interval_s="fast"), "facts.sample_interval_s = 'fast': expected int or float"),
    (lambda d: d["gauges"]["upper"].pop("channel"), "facts.gauges.upper = .*expected the keys"),
    (lambda d: d.update(study_shot=True), "facts.study_shot = True: expected int or null"),
    (lambda d: d["gauges"]["lower"].update(position_m="far"), "facts.gauges.lower.position_m = 'far'"),
])
def test_bad_facts_are_refused_naming_the_field(change, message):
    d = json.loads(json.dumps(FACTS.to_dict()))
    change(d)
    with pytest.raises(InstrumentError, match=message):
        ShotFacts.from_dict(d)


def test_unversioned_facts_of_older_archives_still_read(tmp_path):
    path = tmp_path / "old.h5"
    e = entry(3)
    Archive(path).append([e])
    old = e.facts.to_dict()
    del old["version"], old["study_shot"], old["study"], old["overrides"]
    with h5py.File(path, "r+") as f:  # as an archive written before the version was recorded
        f["shot_000001/truth"].attrs["facts"] = json.dumps(old)
    assert Archive(path).read(1).facts == e.facts


def test_damaged_facts_name_the_shot_and_the_field(tmp_path):
    path = tmp_path / "bad.h5"
    Archive(path).append([entry(4)])
    with h5py.File(path, "r+") as f:
        d = json.loads(f["shot_000001/truth"].attrs["facts"])
        d["gauges"]["upper"]["position_m"] = "far"
        d["unexpected"] = 1
        f["shot_000001/truth"].attrs["facts"] = json.dumps(d)
    with pytest.raises(InstrumentError, match="shot 1: facts.unexpected: unknown key"):
        Archive(path).read(1)
