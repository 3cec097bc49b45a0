"""The emulated scope against its models' programmer manuals (the command lists of
instruments/virtual_scope/manuals/: the MDO3000's and the 4 Series' from the manuals through
tm_devices, the TDS2000's transcribed from its manual, 071-1075), each model on its own: the coverage page
is the measurement of the code; every implemented header answers in its short form as in
its long form; every setting the manual gives as a number (<NR3>) is answered as a number
(NR2 or NR3, never ``50.0m``); every word of the manual an implemented header takes is
taken or refused as a setting not modelled (221)."""
import re
from pathlib import Path

import pytest

from instruments.virtual_scope.coverage import MODELS, events, probe_model, probing_scope, table

DOC = Path(__file__).resolve().parents[2] / "docs" / "reference" / "scpi-coverage.md"
NUMBER = re.compile(r"[-+]?\d+(\.\d+)?(E[-+]?\d+)?")


@pytest.fixture(scope="module")
def probes():
    return {model: probe_model(model) for model in MODELS}


def test_the_coverage_page_is_the_measurement_of_the_code(probes):
    assert table(probes) in DOC.read_text(encoding="utf-8"), (
        "docs/reference/scpi-coverage.md is stale: python -m instruments.virtual_scope.coverage")


@pytest.mark.parametrize("model", MODELS)
def test_the_groups_a_waveform_program_uses_each_answer_something(probes, model):
    groups = {p.command.group for p in probes[model] if p.status == "implemented"}
    assert {"waveform transfer", "horizontal", "trigger", "vertical", "acquisition", "measurement",
            "save and recall set-up", "status and events", "miscellaneous"} <= groups


def short(header: str) -> str:
    """A manual header in its short form (the capitals of each mnemonic), <x> as 1."""
    return ":".join(re.sub(r"[a-z]", "", part) for part in header.replace("<x>", "1").split(":"))


@pytest.mark.parametrize("model", MODELS)
def test_short_and_long_forms_answer_alike_and_numbers_are_nr3(probes, model):
    scope = probing_scope(model)
    session = scope.open_session("conformance")
    checked = 0
    try:
        for p in probes[model]:
            c = p.command
            if p.status != "implemented" or not c.query or p.answer is None or c.header.startswith("*"):
                continue
            if c.header.upper() in ("ALLEV", "EVMSG", "EVENT", "EVQTY", "*ESR", "BUSY", "ACQUIRE:NUMACQ"):
                continue  # each read changes what the next one answers
            session.handle(b"*RST;:HEADER OFF;:VERBOSE ON;*CLS")
            long_form = session.handle(f"{c.concrete}?".encode())
            said = events(session)
            assert session.handle(f"{short(c.concrete)}?".encode()) == long_form, (model, c.header)
            assert events(session) == said and 113 not in said, (model, short(c.concrete))
            if c.args.strip() == "<NR3>":
                assert NUMBER.fullmatch(p.answer), (model, c.header, p.answer)
            checked += 1
    finally:
        scope.close()
    assert checked >= 40, (model, checked)


@pytest.mark.parametrize("model", MODELS)
def test_every_manual_word_of_an_implemented_header_is_taken_or_refused_by_design(probes, model):
    """A word the manual lists for a header the scope implements is taken, or refused as a
    setting not modelled (221): never an illegal value (224) nor a command error (10x).
    (Arming, ACQuire:STATE ON, fires a shot the probing scope refuses: -200, the shot's.)"""
    scope = probing_scope(model)
    session = scope.open_session("conformance")
    try:
        for p in probes[model]:
            if p.status != "implemented" or not p.command.write:
                continue
            for word in p.command.words:
                if "<" in word:
                    continue  # a placeholder (CH<x>), not a word
                root = "" if p.command.concrete.startswith("*") else ":"  # a common command has no path
                session.handle(f"*RST;:HEADER OFF;*CLS;{root}{p.command.concrete} {word}".encode())
                codes = [c for c in events(session) if not (c == 200 and p.command.header == "ACQuire:STATE")]
                assert set(codes) <= {221}, (model, p.command.header, word, codes)
    finally:
        scope.close()
