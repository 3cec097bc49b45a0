"""The TDS2000 as its programmer manual (071-1075) gives it beyond the commands the models
share: the set-up locations *SAV/*RCL and SAVe:SETUp/RECAll:SETUp (1 to 10, kept over *RST),
the manual's other names (CH<x>:VOLts, HORizontal:SECdiv, HDR), its YT display, WFMPre's
ENCdg words ASC and BIN, the set forms of the preamble fields that describe a reference
waveform (-221: none is emulated), and display settings answered as its syntax gives them."""
import pytest

from lab.lab_scope import ask


def test_a_set_up_location_keeps_the_settings_over_rst_and_restores_them_all(make_scope):
    scope, s, _ = make_scope("tds2000")
    s.handle(b"CH1:SCALE 0.2;:HOR:SCALE 1E-3;:TRIG:MAIN:LEVEL 0.05;:SEL:CH2 OFF;:DATA:ENCDG ASCII;"
             b":ACQ:STOPAFTER SEQUENCE;*SAV 3")
    saved, overrides = ask(s, "SET?"), scope.overrides()
    s.handle(b"*RST")
    assert ask(s, "SET?") != saved and ask(s, "CH1:SCALE?;:SEL:CH2?") == "5.0E-2;1"
    s.handle(b"*RCL 3")
    assert ask(s, "SET?") == saved and scope.overrides() == overrides and ask(s, "EVENT?") == "0"
    s.handle(b"RECALL:SETUP FACTORY")
    assert ask(s, "CH1:SCALE?;:SEL:CH2?;:DATA:ENCDG?") == "5.0E-2;1;RIBINARY"
    s.handle(b"SAVE:SETUP 10;:CH1:SCALE 1;:RECALL:SETUP 10")
    assert ask(s, "CH1:SCALE?;:EVENT?") == "5.0E-2;0"


@pytest.mark.parametrize("command, code", [
    ("*RCL 4", 200), ("*SAV 11", 222), ("*SAV 0", 222), ("RECALL:SETUP 2.5", 222),
    ("SAVE:SETUP \"A:\\\\TEK.SET\"", 221), ("RECALL:SETUP \"A:\\\\TEK.SET\"", 221), ("RECALL:SETUP DEFAULT", 224)])
def test_a_location_never_saved_or_out_of_range_or_a_file_is_refused_and_changes_nothing(make_scope, command, code):
    scope, s, _ = make_scope("tds2000")
    s.handle(b"CH1:SCALE 0.5")
    before, overrides = ask(s, "SET?"), scope.overrides()
    s.handle(command.encode())
    assert ask(s, "EVENT?") == str(code) and ask(s, "SET?") == before and scope.overrides() == overrides


def test_the_manuals_other_names_answer_as_the_commands_they_name(make_scope):
    scope, s, _ = make_scope("tds2000")
    s.handle(b"CH2:VOLTS 0.1;:HOR:MAIN:SECDIV 2.5E-4;:HDR ON")
    assert ask(s, "CH2:SCALE?") == ":CH2:SCALE 1.0E-1"
    s.handle(b"HEADER OFF")
    assert ask(s, "CH2:VOLTS?;:HOR:SECDIV?;:HOR:SCALE?;:HDR?") == "1.0E-1;2.5E-4;2.5E-4;0"
    assert ask(s, "EVENT?") == "0"


def test_the_display_is_yt_and_its_settings_answer_as_the_syntax_gives_them(make_scope):
    scope, s, _ = make_scope("tds2000")
    before = scope.overrides()
    assert ask(s, "DISPLAY:FORMAT?") == "YT"
    s.handle(b"DISPLAY:FORMAT XY")
    assert ask(s, "EVENT?;:DIS:FORM?") == "221;YT"
    s.handle(b"DISPLAY:PERSISTENCE 5;:DISPLAY:CONTRAST 50.4")
    assert ask(s, "DIS:PERS?;CONTR?;:EVENT?") == "5;50;0"  # DISplay:CONTRast <NR1>: an integer
    s.handle(b"DISPLAY:PERSISTENCE 3")  # not one of 1, 2, 5, INF, OFF
    assert ask(s, "EVENT?;:DIS:PERS?") == "224;5"
    assert scope.overrides() == before


def test_the_preambles_encoding_words_are_asc_and_bin_and_reference_fields_are_not_set(make_scope):
    scope, s, _ = make_scope("tds2000")
    s.handle(b"WFMPRE:ENCDG ASC")
    assert ask(s, "DATA:ENCDG?;:WFMPRE:ENCDG?;:EVENT?") == "ASCII;ASC;0"
    s.handle(b"WFMPRE:ENCDG BIN")
    assert ask(s, "DATA:ENCDG?;:EVENT?") == "RIBINARY;0"
    s.handle(b"WFMPRE:ENCDG BINARY")  # the MDO3000's word, not the TDS's
    assert ask(s, "EVENT?") == "224"
    before = ask(s, "WFMPRE?")
    for field in ("XINCR 1E-6", "YMULT 1", "YUNIT \"A\"", "PT_FMT ENV"):
        s.handle(f"WFMPRE:{field}".encode())
        assert ask(s, "EVENT?") == "221", field
    assert ask(s, "WFMPRE?") == before
