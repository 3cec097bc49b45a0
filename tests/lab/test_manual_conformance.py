"""The emulated scope against its models' programmer manuals (the command trees of
instruments/virtual_scope/manuals/, from the manuals through tm_devices): the coverage page
is the measurement of the code; every implemented header answers in its short form as in
its long form; every setting the manual gives as a number (<NR3>) is answered as a number
(NR2 or NR3, never ``50.0m``); no implemented header refuses a word of the manual as a
syntax error."""
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
    for model in MODELS:  # the groups a waveform program uses each answer something
        groups = {p.command.group for p in probes[model] if p.status == "implemented"}
        assert {"waveform transfer", "horizontal", "trigger", "vertical", "acquisition", "measurement",
                "save and recall set-up", "status and events", "miscellaneous"} <= groups


def short(header: str) -> str:
    """A manual header in its short form (the capitals of each mnemonic), <x> as 1."""
    return ":".join(re.sub(r"[a-z]", "", part) for part in header.replace("<x>", "1").split(":"))


def test_short_and_long_forms_answer_alike_and_numbers_are_nr3(probes):
    for model in MODELS:
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
                if "<NR3>" in c.args:
                    assert NUMBER.fullmatch(p.answer), (model, c.header, p.answer)
                checked += 1
        finally:
            scope.close()
        assert checked >= 40, (model, checked)


def test_no_implemented_header_takes_a_manual_word_as_a_syntax_error(probes):
    """A word of the manual may be refused (221, or 224 where the emulation lacks it), but
    never parsed as something else: no 10x command error for a manual word."""
    for model in MODELS:
        scope = probing_scope(model)
        session = scope.open_session("conformance")
        try:
            for p in probes[model]:
                if p.status != "implemented" or not p.command.write:
                    continue
                for word in p.command.words:
                    if "<" in word:
                        continue  # a placeholder (CH<x>), not a word
                    session.handle(f"*RST;:HEADER OFF;*CLS;:{p.command.concrete} {word}".encode())
                    codes = events(session)
                    assert not any(100 <= abs(code) < 200 for code in codes), (model, p.command.header, word, codes)
        finally:
            scope.close()
