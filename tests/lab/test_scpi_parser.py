"""The SCPI parser: units split outside strings and blocks, headers in every form,
arguments of every kind, numbers with suffix multipliers, and the error each fault gives."""
import pytest

from instruments.scpi.blocks import block_payload, definite_block
from instruments.scpi.numbers import number
from instruments.scpi.parser import parse_unit, split_units
from instruments.scpi.status import ScpiError
from instruments.scpi.tree import CommandTree, Mnemonic


def test_units_split_on_semicolons_outside_strings_and_blocks():
    block = definite_block(b"a;b\n;")
    message = b'DAT:ENC RIB;:CH1:SCA 0.1;MEAS:LABEL "x;y";DATA ' + block + b";*IDN?"
    units = split_units(message)
    assert units[:3] == ["DAT:ENC RIB", ":CH1:SCA 0.1", 'MEAS:LABEL "x;y"']
    assert units[4] == "*IDN?" and len(units) == 5
    assert parse_unit(units[3]).args[0].text.encode("latin-1") == b"a;b\n;"


@pytest.mark.parametrize("text, mnemonics, query, absolute, common", [
    (":DATa:SOUrce?", ("DATA", "SOURCE"), True, True, False),
    ("dat:sou ch1", ("DAT", "SOU"), False, False, False),
    ("*idn?", ("*IDN",), True, True, True),
    ("  CH2:SCALE\t50mV ", ("CH2", "SCALE"), False, False, False),
    ("WFMPRE:BYT_NR?", ("WFMPRE", "BYT_NR"), True, False, False),
])
def test_header_forms(text, mnemonics, query, absolute, common):
    unit = parse_unit(text)
    assert (unit.mnemonics, unit.query, unit.absolute, unit.common) == (mnemonics, query, absolute, common)


def test_argument_kinds():
    unit = parse_unit('X 1.5E-3, RIBinary, "say ""hi""", \'it\', #15hello, 10 us, #HFF')
    kinds = [(a.kind, a.text) for a in unit.args]
    assert kinds == [("number", "1.5E-3"), ("word", "RIBinary"), ("string", 'say "hi"'), ("string", "it"),
                     ("block", "hello"), ("number", "10 us"), ("number", "#HFF")]


@pytest.mark.parametrize("text, unit, value", [
    ("50mV", "V", 0.05), ("10 us", "S", 1e-5), ("2.5MHz", "HZ", 2.5e6), ("1MAHZ", "HZ", 1e6),
    ("20E6", "HZ", 20e6), ("-3.2", "", -3.2), ("5ns", "S", 5e-9), ("1KS", "S", 1e3), ("#B101", "", 5.0),
    ("#Q17", "", 15.0), ("0.9 v", "V", 0.9)])
def test_numbers_with_suffix_multipliers(text, unit, value):
    assert number(text, unit) == pytest.approx(value, rel=1e-12)


@pytest.mark.parametrize("text, unit, code", [("5 mA", "V", -131), ("abc", "V", -104), ("5 Hz", "S", -131),
                                              ("#HXZ", "", -104), ("1e999", "V", -120)])
def test_bad_numbers(text, unit, code):
    with pytest.raises(ScpiError) as e:
        number(text, unit)
    assert e.value.code == code


@pytest.mark.parametrize("message, code", [(b'A "open', -150), (b"A #3ab", -160), (b"A #9123", -160)])
def test_bad_messages(message, code):
    with pytest.raises(ScpiError) as e:
        split_units(message)
    assert e.value.code == code


@pytest.mark.parametrize("text, code", [("DAT::ENC", -102), ("DAT:ENC??", -102), ("1DAT", -102),
                                        ("DAT:ENC RIB,", -109), ("DAT:ENC RIB RPB", -103), ("X @", -141),
                                        ("D\u00e9t", -101)])
def test_bad_units(text, code):
    with pytest.raises(ScpiError) as e:
        parse_unit(text)
    assert e.value.code == code


def test_blocks_round_trip():
    for data in (b"", b"x", bytes(range(256)) * 50):
        block = definite_block(data)
        assert block.startswith(b"#") and block_payload(block) == data
    assert block_payload(b"#0abc") == b"abc"
    with pytest.raises(ValueError):
        block_payload(b"#15abc")


def test_mnemonics_match_their_short_and_long_forms_only():
    m = Mnemonic("ENCdg")
    assert (m.long, m.short) == ("ENCDG", "ENC")
    assert m.match("ENC") is None and m.match("ENCDG") is None
    assert m.match("ENCD") is False and m.match("EN") is False
    ch = Mnemonic("CH<n>")
    assert ch.match("CH3") == 3 and ch.match("CH") == 1 and ch.match("CHA") is False
    tree = CommandTree()
    tree.add("MEASUrement:MEAS<n>:VALue", read=lambda c: None)
    found = tree.find(("MEASU", "MEAS2", "VAL"))
    assert found.suffixes == (None, 2, None)
    assert found.header(True) == ":MEASUREMENT:MEAS2:VALUE" and found.header(False) == ":MEASU:MEAS2:VAL"
    with pytest.raises(ValueError):
        tree.add("measurement:meas<n>:value", read=lambda c: None)


def test_a_truncating_tree_takes_every_spelling_between_the_forms_and_prefers_an_exact_one():
    strict, tek = CommandTree(), CommandTree(truncation=True)
    for tree in (strict, tek):
        tree.add("DATa:SOUrce", read=lambda c: "source")
        tree.add("DATa:SOUrcex", read=lambda c: "other")  # a sibling the truncation of the first could name
        tree.add("CH<n>:SCAle", read=lambda c: None)
    assert strict.find(("DATA", "SOUR")) is None
    for spelling in ("SOU", "SOUR", "SOURC", "SOURCE"):
        assert tek.find(("DATA", spelling)).header(True) == ":DATA:SOURCE"
    assert tek.find(("DATA", "SOURCEX")).header(True) == ":DATA:SOURCEX"
    assert tek.find(("DA", "SOURCE")) is None and tek.find(("DATA", "SOURCEXY")) is None
    assert tek.find(("DATA", "SO")) is None and tek.find(("DATA", "SOUX")) is None
    assert tek.find(("CH2", "SCAL")).suffixes == (2, None)
