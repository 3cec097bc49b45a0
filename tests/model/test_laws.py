"""The contact-law registry (rig.model.laws): one module per law, and everything that
names a law's parameters reads them from it."""
import pickle
from pathlib import Path

import pytest

from rig import Bead, RigError, Wall
from rig.experiment.scene import SCHEMA, key_spec
from rig.experiment.shot import Rig
from rig.fit.parameters import law_overrides, parse_parameter, parse_parameters
from rig.model.chain import Chain
from rig.model.contact import CONTACT_LAWS, HERTZ, KUWABARA_KONO, contact_law
from rig.model.laws import LAWS, OWNER, PARAMETERS


def chain(**kw):
    return Chain([Bead("ptfe", "4.76 mm", "0.1226 g")] * 3, wall=Wall("brass"), **kw)


def test_registry_is_what_contact_reexports():
    assert {law.name: law for law in LAWS} == CONTACT_LAWS
    assert contact_law("Dashpot") is CONTACT_LAWS["dashpot"]
    assert CONTACT_LAWS["hertz"].code == HERTZ and not CONTACT_LAWS["hertz"].dissipative
    kk = CONTACT_LAWS["kuwabara-kono"]
    assert kk.code == KUWABARA_KONO and kk.parameter == "damping_time" and kk.dissipative
    for law in LAWS:  # every law says its equation and where it comes from
        assert "=" in law.description or "A delta^n" in law.description


def test_scene_schema_and_fit_keys_derive_from_the_registry():
    for key, p in PARAMETERS.items():
        assert SCHEMA["chain"][key] == p.scene_spec == key_spec(f"chain.{key}")
    assert SCHEMA["chain"]["damping_time"] == "s" and SCHEMA["chain"]["contact_exponent"] is float
    for key, laws in OWNER.items():  # fitting a law's key selects its first law
        law = laws[0]
        p = PARAMETERS[key]
        lo, hi = (p.lo or 1e-3), min(p.hi, (p.lo or 1e-3) * 3)
        unit = "" if p.unit == "1" else f" {p.unit}"
        param = parse_parameter(f"chain.{key}={lo!r}{unit}:{hi!r}{unit}")
        assert law_overrides([param]) == [f"chain.contact_law={law.name}"]


@pytest.mark.parametrize("kw, words", [
    ({"contact_law": "dashpot"}, "chain.contact_damping = 0.0: contact law 'dashpot' needs it > 0"),
    ({"damping_time": 1e-6}, "chain.damping_time = 1e-06: belongs to contact law 'kuwabara-kono', not 'hertz'"),
    ({"contact_law": "dashpot", "contact_damping": -1.0}, "chain.contact_damping = -1.0: must be >= 0 kg/s"),
    ({"contact_exponent": 3.5}, "chain.contact_exponent = 3.5: a number in [1, 3] (default 1.5)"),
    ({"contact_exponent": "1.5"}, "chain.contact_exponent = '1.5'"),
    ({"reference_force": 0.0}, "chain.reference_force = 0.0: must be > 0 N"),
    ({"stiffness": 1.0}, "chain = 'stiffness': not a contact parameter"),
])
def test_chain_refuses_a_law_parameter_in_one_line(kw, words):
    with pytest.raises(RigError) as err:
        chain(**kw)
    assert words in str(err.value) and "\n" not in str(err.value)


def test_chain_takes_every_parameter_as_an_attribute():
    c = chain(contact_law="kuwabara-kono", damping_time="2 us")
    assert c.damping_time == pytest.approx(2e-6, rel=1e-15) and c.contact_damping == 0.0
    assert c.contact_exponent == 1.5 and c.reference_force == 1.0
    tau, mu = c.contact_dissipation()[:2]
    assert tau.max() == pytest.approx(2e-6, rel=1e-15) and not mu.any()


def test_chain_declares_every_parameter_for_type_checkers():
    """Chain's class annotations (what mypy and editors see) name each law parameter the
    chain sets as an attribute, no more and no fewer."""
    declared = {name for name, kind in Chain.__annotations__.items() if kind == "float"}
    assert declared == set(PARAMETERS)


def test_fit_bounds_outside_the_law_are_refused_before_solving():
    with pytest.raises(RigError, match=r"chain.contact_exponent = 0.5: a number in \[1, 3\]"):
        parse_parameter("chain.contact_exponent=0.5:2")


def test_laws_and_chains_pickle():
    """A study's worker processes receive chains (spawn): every law travels by reference."""
    for law in LAWS:
        assert pickle.loads(pickle.dumps(law)) == law
    c = pickle.loads(pickle.dumps(chain(contact_law="powerlaw-dashpot", dashpot_gamma=0.5, dashpot_exponent=0.7)))
    assert c.law == CONTACT_LAWS["powerlaw-dashpot"]
    assert c.contact_dissipation()[2].min() == pytest.approx(0.7, rel=1e-15)


def test_a_fitted_law_key_builds_its_chain():
    """rig fit's overrides of a candidate (law_overrides + each key's --set text) assemble
    the scene's chain with that law and those values."""
    params = parse_parameters(["chain.dashpot_gamma=0.05:2", "chain.dashpot_exponent=0.3:2"])
    sets = law_overrides(params) + [p.override(v) for p, v in zip(params, (0.4, 0.6))]
    c = Rig.from_scene("ptfe20_gravity", sets).chain
    assert c.law.name == "powerlaw-dashpot" and (c.dashpot_gamma, c.dashpot_exponent) == (0.4, 0.6)
    assert {p.unit for p in params} == {"1"}


def test_the_model_page_names_every_law_and_key():
    """The model page's table of laws (docs/explanation/model.md, where the README's went) is
    written by hand: it must keep up with the registry."""
    text = (Path(__file__).resolve().parents[2] / "docs" / "explanation" / "model.md").read_text()
    for law in LAWS:
        assert f'"{law.name}"' in text or law.name == "hertz", law.name
    for key in PARAMETERS:
        assert f"chain.{key}" in text, key
