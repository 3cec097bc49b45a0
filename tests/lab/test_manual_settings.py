"""The rest of each model's manual that waveform programs meet (manual_settings.py): group
queries (``CH<x>?``, ``HORizontal?``, ``ACQuire?``), ``ID?``, ``LOCk``/``UNLock``, ``REM``,
``FACtory``, ``ACQuire:MAXSamplerate?`` and the settings emulated at one value; each only
where the model's manual lists it (an unseen MDO3000 program timed out on ``CH1?``)."""
import re

import pytest

from lab.lab_scope import ask

MODELS = ["tds2000", "mdo3000", "mso4"]


def events(s) -> list:
    """The codes of the events queued since the last call."""
    return [int(code) for code in re.findall(r'(?:^|[ ,])(-?\d+),"', ask(s, "ALLEV?")) if int(code) != 0]


@pytest.mark.parametrize("personality", MODELS)
def test_a_group_query_answers_its_settings_as_their_own_queries_do_and_restores_them_sent_back(
        make_scope, personality):
    scope, s, _ = make_scope(personality)
    s.handle(b"CH1:SCALE 0.1;POSITION -2;COUPLING AC")
    s.handle(b"HEADER ON")
    group = ask(s, "CH1?")
    assert group.startswith(":CH1:SCALE ") and ";POSITION " in group and ";COUPLING AC" in group, group
    names = [part.split(" ")[0].split(":")[-1] for part in group.split(";")]
    s.handle(b"HEADER OFF")
    one_by_one = ask(s, ";:".join(f"CH1:{n}?" for n in names))  # each setting's own query, in the group's order
    assert ask(s, "CH1?") == one_by_one and events(s) == []
    assert len(names) == len(set(names)) and "VOLTS" not in names  # the TDS2000's other name answered once
    s.handle(b"*RST")
    assert ask(s, "CH1:SCALE?;COUPLING?") != one_by_one.split(";")[0] + ";AC"
    s.handle(group.encode())  # the HEADer ON reply is a command that restores the group
    assert ask(s, "CH1?") == one_by_one and events(s) == []


@pytest.mark.parametrize("personality", MODELS)
def test_horizontal_and_acquisition_groups_hold_settings_not_results(make_scope, personality):
    scope, s, _ = make_scope(personality)
    s.handle(b"HEADER ON")
    acquire = ask(s, "ACQUIRE?")
    assert acquire.startswith(":ACQUIRE:") and "NUMACQ" not in acquire  # a count of records, not a setting
    assert ":HORIZONTAL:" in ask(s, "HORIZONTAL?") and events(s) == []
    if personality == "tds2000":  # its manual's HORizontal:MAIn? and the measurement's settings
        assert ask(s, "HOR:MAIN?").startswith(":HORIZONTAL:MAIN:SCALE ")
        assert ask(s, "MEASU:MEAS1?") == ":MEASUREMENT:MEAS1:TYPE PK2PK;STATE 0" and events(s) == []
    else:  # not in the MDO3000's or the 4 Series' manual
        s.handle(b"HOR:MAIN?")
        assert events(s) == [113]


@pytest.mark.parametrize("personality, idn, expected", [
    ("tds2000", "TEKTRONIX,TPS 2024B,0,CF:91.1CT FV:v11.10", "TEK/TPS 2024B,CF:91.1CT,FV:v11.10"),
    ("mdo3000", None, "TEK/MDO3024,CF:91.1CT,FV:v1.30"),
])
def test_id_is_the_manuals_form_of_the_idn(make_scope, personality, idn, expected):
    scope, s, _ = make_scope(personality, idn=idn)
    assert ask(s, "ID?") == expected


@pytest.mark.parametrize("personality", MODELS)
def test_lock_unlock_rem_and_factory(make_scope, personality):
    scope, s, _ = make_scope(personality)
    assert ask(s, "LOCK?") == "NONE"
    s.handle(b"LOCK ALL")
    assert ask(s, "LOCK?") == "ALL"
    s.handle(b'UNLOCK ALL;:REM "a comment: nothing done"')
    assert ask(s, "LOCK?") == "NONE" and events(s) == []
    s.handle(b"*RST")
    factory = ask(s, "SET?")
    s.handle(b"CH1:SCALE 1.0;:ACQUIRE:STOPAFTER SEQUENCE")
    assert ask(s, "SET?") != factory
    s.handle(b"FACTORY")
    assert ask(s, "SET?") == factory and events(s) == []


@pytest.mark.parametrize("personality, header, taken, refused, answer", [
    ("tds2000", "CH1:INVERT", "OFF", "ON", "OFF"),
    ("tds2000", "CH1:YUNIT", '"V"', '"A"', '"V"'),
    ("tds2000", "SELECT:MATH", "OFF", "ON", "0"),
    ("tds2000", "SELECT:REFB", "OFF", "1", "0"),
    ("tds2000", "HORIZONTAL:VIEW", "MAIN", "WINDOW", "MAIN"),
    ("mdo3000", "CH2:IMPEDANCE", "MEG", "FIFTY", "MEG"),
    ("mdo3000", "CH2:IMPEDANCE", "MEG", "50", "MEG"),
    ("mso4", "CH3:INVERT", "OFF", "1", "OFF"),
])
def test_a_setting_emulated_at_one_value_refuses_the_manuals_others_and_never_takes_them(
        make_scope, personality, header, taken, refused, answer):
    scope, s, _ = make_scope(personality)
    s.handle(f"{header} {taken}".encode())
    assert events(s) == [] and ask(s, f"{header}?") == answer
    s.handle(f"{header} {refused}".encode())
    assert events(s) == [221] and ask(s, f"{header}?") == answer
    s.handle(f"{header} NOSUCHWORD".encode())
    assert events(s) == [224]


@pytest.mark.parametrize("personality, command", [
    ("mdo3000", "CH1:YUNIT?"), ("mso4", "SELECT:MATH?"), ("mso4", "CH1:IMPEDANCE?"), ("mdo3000", "HOR:VIEW?"),
])
def test_a_command_of_another_models_manual_stays_undefined(make_scope, personality, command):
    scope, s, _ = make_scope(personality)
    assert s.handle(command.encode()) == b"" and events(s) == [113]


@pytest.mark.parametrize("idn, rate", [("TEKTRONIX,MDO3012,C000000,CF:91.1CT FV:v1.30", "2.5000E+9"),
                                       ("TEKTRONIX,MDO3104,C000000,CF:91.1CT FV:v1.30", "5.0000E+9")])
def test_the_mdo3000s_max_sample_rate_is_its_models(make_scope, idn, rate):
    scope, s, _ = make_scope("mdo3000", idn=idn)
    assert ask(s, "ACQUIRE:MAXSAMPLERATE?") == ask(s, "CONFIGURATION:ANALOG:MAXSAMPLERATE?") == rate


@pytest.mark.parametrize("personality", ["mdo3000", "mso4"])
def test_the_trigger_holdoff_is_kept_within_the_manuals_range(make_scope, personality):
    """An unseen program waited 5 s on TRIGger:A:HOLDoff:TIMe? (113, no answer)."""
    scope, s, _ = make_scope(personality)
    assert float(ask(s, "TRIGGER:A:HOLDOFF:TIME?")) == 0.0
    s.handle(b"TRIGGER:A:HOLDOFF:TIME 250ms")
    assert float(ask(s, "TRIG:A:HOLD:TIM?")) == 0.25 and events(s) == []
    for bad in (b"TRIGGER:A:HOLDOFF:TIME 10.5", b"TRIGGER:A:HOLDOFF:TIME -1E-9"):
        s.handle(bad)
        assert events(s) == [222] and float(ask(s, "TRIGGER:A:HOLDOFF:TIME?")) == 0.25


def test_the_4_series_external_attenuation_is_one_and_refuses_others(make_scope):
    scope, s, _ = make_scope("mso4")
    assert float(ask(s, "CH2:PROBEFUNC:EXTATTEN?")) == 1.0
    s.handle(b"CH2:PROBEFUNC:EXTATTEN 1")
    assert events(s) == []
    s.handle(b"CH2:PROBEFUNC:EXTATTEN 10")  # would scale the channel's volts: not modelled, not taken
    assert events(s) == [221] and float(ask(s, "CH2:PROBEFUNC:EXTATTEN?")) == 1.0
    s.handle(b"CH2:PROBEFUNC:EXTATTEN 1E11")
    assert events(s) == [222]
