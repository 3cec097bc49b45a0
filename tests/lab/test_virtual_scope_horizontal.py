"""The horizontal couplings of the 4 Series manual (HORizontal:MODe, MODe:RECOrdlength,
MODe:SAMPLERate, MODe:SCAle, MODe:MANual:CONFIGure): AUTO after *RST keeps the scale, MANual
keeps the sample rate, the rate never past the MSO44's 6.25 GS/s; the MDO3000's and TDS2000's
manuals have no HORizontal:MODe (113)."""
import pytest

from lab.lab_scope import ask

MSO44_RATE = "6.2500E+9"


def test_manual_mode_keeps_the_sample_rate_and_a_record_length_moves_the_scale(make_scope):
    """HORizontal:MODe MANual "lets you change the sample rate, horizontal scale, and record
    length. These values interact. For example, when you change record length then the
    horizontal scale also changes": 1,000 points at 6.25 GS/s span 160 ns, 16 ns/div."""
    _scope, s, _ = make_scope("mso4")
    s.handle(b"HORizontal:MODe MANual;:HORizontal:MODe:SAMPLERate 6.25e9;:HORizontal:RECOrdlength 1000")
    assert ask(s, "HORizontal:MODe:SAMPLERate?;:HORizontal:SCAle?;:HORizontal:RECOrdlength?") == \
        f"{MSO44_RATE};16.0000E-9;1000"
    s.handle(b"HORizontal:SCAle 1E-6")  # the rate kept: 62,500 points, the model's nearest 50,000
    assert ask(s, "HOR:SAMPLER?;:HOR:RECO?;:HOR:SCA?") == f"{MSO44_RATE};50000;800.0000E-9"
    assert ask(s, "ALLEV?") == '0,"No events to report - queue empty"'


def test_a_sample_rate_past_the_models_is_its_maximum(make_scope):
    """The MSO44 samples at most 6.25 GS/s in real time (4 Series MSO datasheet): a higher
    rate asked is that one, in either mode."""
    _scope, s, _ = make_scope("mso4")
    s.handle(b"HOR:MODE MANUAL;:HOR:MODE:SAMPLERATE 1E11")
    assert ask(s, "HOR:MODE:SAMPLERATE?;:ALLEV?") == f'{MSO44_RATE};0,"No events to report - queue empty"'
    s.handle(b"HOR:MODE AUTO;:HOR:SCALE 2E-8;:HOR:MODE:SAMPLERATE 1E11")
    assert ask(s, "HOR:SCALE?;:HOR:RECO?;:HOR:SAMPLERATE?") == "20.0000E-9;1000;5.0000E+9"


def test_auto_mode_after_rst_keeps_the_scale_and_the_rate_within_the_models(make_scope):
    """AUTO, the 4 Series' mode after *RST, "automatically adjusts the sample rate and record
    length": the scale is the client's; a record the rate cannot fill at it (10,000 points at
    20 ns/div: 50 GS/s) is the longest that fits (1,000 points, 5 GS/s); below 16 ns/div even
    1,000 points need more (the real scope interpolates): the shortest record."""
    _scope, s, _ = make_scope("mso4")
    s.handle(b"HOR:MODE MANUAL;:HOR:MODE:MANUAL:CONFIGURE RECORDLENGTH;*RST")
    assert ask(s, "HOR:MODE?;:HOR:MODE:MANUAL:CONFIGURE?") == "AUTO;HORIZONTALSCALE"
    s.handle(b"HOR:SCALE 2E-8;:HOR:RECO 10000")
    assert ask(s, "HOR:SCALE?;:HOR:RECO?;:HOR:SAMPLERATE?") == "20.0000E-9;1000;5.0000E+9"
    s.handle(b"HOR:SCALE 1E-4;:HOR:RECO 20000")  # within the rate: the record set, the scale kept
    assert ask(s, "HOR:SCALE?;:HOR:RECO?;:HOR:SAMPLERATE?") == "100.0000E-6;20000;20.0000E+6"
    s.handle(b"HOR:SCALE 1E-9")
    assert ask(s, "HOR:SCALE?;:HOR:RECO?") == "1.0000E-9;1000"


def test_manual_configure_names_what_a_new_sample_rate_moves(make_scope):
    """HORizontal:MODe:MANual:CONFIGure: "which horizontal control (scale or record length)
    will primarily change when the sample rate is changed in Manual mode"."""
    _scope, s, _ = make_scope("mso4")
    s.handle(b"HOR:MODE MANUAL;:HOR:MODE:SAMPLERATE 5E6")  # 10,000 points: 200 us/div
    assert ask(s, "HOR:SCALE?;:HOR:RECO?") == "200.0000E-6;10000"
    s.handle(b"HOR:MODE:SAMPLERATE 10E6")  # HORIZontalscale: the scale moves
    assert ask(s, "HOR:SCALE?;:HOR:RECO?") == "100.0000E-6;10000"
    s.handle(b"HOR:MODE:MANUAL:CONFIGURE RECORDL;:HOR:MODE:SAMPLERATE 20E6")  # RECORDLength: the record
    assert ask(s, "HOR:SCALE?;:HOR:RECO?;:HOR:SAMPLERATE?") == "100.0000E-6;20000;20.0000E+6"


@pytest.mark.parametrize("personality", ["tds2000", "mdo3000"])
def test_models_without_horizontal_modes_answer_113(make_scope, personality):
    """The MDO3000's and TDS2000's manuals have no HORizontal:MODe: scale and record length
    are set alone, each keeping the other."""
    _scope, s, _ = make_scope(personality)
    for query in (b"HORIZONTAL:MODE?", b"HORIZONTAL:MODE:SCALE?", b"HORIZONTAL:MODE:RECORDLENGTH?"):
        assert s.handle(query) == b"" and ask(s, "EVENT?") == "113"


def test_set_query_restores_a_manual_mode_setup(make_scope):
    """SET? of the 4 Series holds the mode, what a new rate moves and the sample rate before
    the record length and scale: sent back after *RST (AUTO), the set-up is the same."""
    _scope, s, _ = make_scope("mso4")
    s.handle(b"HOR:MODE MANUAL;:HOR:MODE:MANUAL:CONFIGURE RECORDL;:HOR:MODE:SAMPLERATE 6.25E9;:HOR:RECO 1000")
    state = "HOR:MODE?;:HOR:MODE:MANUAL:CONFIGURE?;:HOR:SAMPLERATE?;:HOR:RECO?;:HOR:SCALE?"
    before = ask(s, state)
    setup = s.handle(b"SET?").rstrip(b"\n")
    s.handle(b"*RST")
    assert ask(s, state) != before
    s.handle(setup)
    assert ask(s, state) == before == f"MANUAL;RECORDLENGTH;{MSO44_RATE};1000;16.0000E-9"
    assert ask(s, "ALLEV?") == '0,"No events to report - queue empty"'


@pytest.mark.parametrize("idn, rate", [("TEKTRONIX,MDO3024,C010001,CF:91.1CT FV:v1.30", "2.5000E+9"),
                                       ("TEKTRONIX,MDO3054,C010001,CF:91.1CT FV:v1.30", "5.0000E+9")])
def test_the_mdo3000_keeps_to_its_models_sample_rate(make_scope, idn, rate):
    """MDO3000 datasheet: 2.5 GS/s on the 100 to 350 MHz models, 5 GS/s on the 500 MHz and
    1 GHz ones. 10,000 points at 400 ns/div need 2.5 GS/s: kept on both; at 200 ns/div they
    need 5 GS/s: kept on the MDO3054, the MDO3024's longest record within 2.5 GS/s (1,000
    points) on it; RECOrdlength 10000 there stays within it too; at 20 ns/div even 1,000
    points need 5 GS/s: the shortest record. HORizontal:SAMPLERate's "command form is
    ignored" (MDO3000 manual)."""
    _scope, s, _ = make_scope("mdo3000", idn=idn)
    state = "HOR:SCALE?;:HOR:RECO?;:HOR:SAMPLERATE?"
    s.handle(b"HOR:RECO 10000;:HOR:SCALE 4E-7")
    assert ask(s, state) == "400.0000E-9;10000;2.5000E+9"
    s.handle(b"HOR:SCALE 2E-7;:HOR:RECO 10000")
    assert ask(s, state) == ("200.0000E-9;10000;5.0000E+9" if rate == "5.0000E+9" else "200.0000E-9;1000;500.0000E+6")
    assert ask(s, "CONFIG:ANALOG:MAXSAMPLERATE?") == rate
    s.handle(b"HOR:SCALE 2E-8")
    assert ask(s, state) == "20.0000E-9;1000;5.0000E+9"
    s.handle(b"HOR:SCALE 1E-3;:HOR:RECO 10000;:HOR:SAMPLERATE 1E9")
    assert ask(s, state + ";:ALLEV?") == '1.0000E-3;10000;1.0000E+6;0,"No events to report - queue empty"'


@pytest.mark.parametrize("asked, taken", [("1E-9", "5.0E-9"), ("2.6E-9", "5.0E-9"), ("5E-9", "5.0E-9"),
                                          ("7E-9", "5.0E-9"), ("1E3", "5.0E1")])
def test_a_tds2000_scale_beyond_its_time_base_is_taken_at_the_nearer_end(make_scope, asked, taken):
    """The TDS2000C's time base runs "5 ns/div to 50 s/div, in a 1, 2.5, 5 sequence" (its user
    manual's horizontal specifications); a numeric argument is "forced to a valid setting":
    beyond the range, the nearer end, without an error; 2,500 points over ten divisions."""
    _scope, s, _ = make_scope("tds2000")
    s.handle(f"HORIZONTAL:MAIN:SCALE {asked}".encode())
    assert ask(s, "HORIZONTAL:MAIN:SCALE?") == taken
    assert ask(s, "WFMPRE:XINCR?") == _scope.personality.number(float(taken) * 10 / 2500)
    assert ask(s, "ALLEV?") == '0,"No events to report - queue empty"'
