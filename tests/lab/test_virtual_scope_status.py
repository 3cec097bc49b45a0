"""The status model's enable registers and the configuration queries, from the manuals'
text: DESE (the DESER masks which events set SESR bits and enter the queue), *PSC (the
power-on flag: DESER 255, ESER and SRER 0 at power-on), the CONFIGuration queries of the
MDO3000 (the emulated model's channels, bandwidth and record lengths; options absent, 0)."""
import pytest

from lab.lab_scope import ask

CME, EXE, OPC = 32, 16, 1


@pytest.mark.parametrize("personality", ["tds2000", "mdo3000", "mso4"])
def test_dese_masks_the_events_it_clears_from_the_esr_and_the_queue(make_scope, personality):
    """DESE (MDO3000 and 4 Series manuals): "the mask that determines whether events are
    reported to the Standard Event Status Register (SESR), and entered into the Event Queue";
    ``DESE 209`` sets 11010001. At power-on (*PSC 1) it is 255; *RST and *CLS leave it."""
    _scope, s, _ = make_scope(personality)
    assert ask(s, "DESE?;*PSC?") == "255;1"
    s.handle(b"DESE 209;*CLS")
    assert ask(s, "DESE?") == "209"  # 11010001: OPC, EXE, CME on; QYE, DDE, URQ... off but PON
    s.handle(b"DESE 255")
    s.handle(f"DESE {255 - CME};:NO:SUCH:HEADER".encode())  # CME masked: no bit, no event
    assert ask(s, "*ESR?;:EVQTY?") == "0;0"
    s.handle(f"DESE {255 - EXE};:CH1:SCALE -1".encode())  # an execution error (222), masked
    assert ask(s, "*ESR?;:EVQTY?") == "0;0"
    s.handle(b"*RST;*CLS;:NO:SUCH:HEADER")  # *RST and *CLS keep the DESER: CME let through
    assert ask(s, "DESE?;*ESR?;:EVQTY?") == f"{255 - EXE};{CME};1"
    s.handle(f"*CLS;:DESE {255 - OPC};*OPC".encode())  # the OPC bit, masked
    assert ask(s, "*ESR?") == "0"
    s.handle(b"DESE 255;*OPC")
    assert ask(s, "*ESR?") == str(OPC)
    s.handle(b"DESE 256")
    assert ask(s, "DESE?;:EVENT?") == "255;222"


def test_psc_is_kept_and_answered(make_scope):
    """*PSC {ON|OFF|<NR1>}: 0 (or OFF) false, any other value true; the DESER, ESER and SRER
    as they were (the flag acts at power-on only)."""
    _scope, s, _ = make_scope("mso4")
    s.handle(b"*ESE 60;*SRE 32;DESE 100;*PSC OFF")
    assert ask(s, "*PSC?;*ESE?;*SRE?;:DESE?") == "0;60;32;100"
    s.handle(b"*PSC 7")
    assert ask(s, "*PSC?") == "1"
    s.handle(b"*PSC 0")
    assert ask(s, "*PSC?") == "0"


def test_the_mdo3000_configuration_is_the_emulated_models(make_scope):
    """The queries tekinstr asks: ANALOg:NUMCHANnels "the number of analog channels" (4 on an
    MDO3024), the options and features not emulated 0 (ADVMATH, AFG, ARB, AUXIN, DVM,
    APPLications:POWer, DIGITAl:NUMCHANnels, RF:NUMCHANnels "If no RF channels are present,
    the query returns 0"), NUMMEAS the measurements there are (8), RECLENS the record lengths
    taken, ANALOg:BANDWidth the model's (MDO3024: 200 MHz), GNDCPLG "always returns 0"."""
    _scope, s, _ = make_scope("mdo3000", max_record_length=1_000_000)
    asked = ("ADVMATH", "AFG", "APPLICATIONS:POWER", "ARB", "AUXIN", "DVM", "ANALOG:NUMCHANNELS",
             "DIGITAL:NUMCHANNELS", "NUMMEAS", "RF:NUMCHANNELS")
    assert ask(s, ";".join(f":CONFIGURATION:{q}?" for q in asked)) == "0;0;0;0;0;0;4;0;8;0"
    assert ask(s, "CONFIG:ANALO:RECLENS?;BANDW?;MAXBANDW?;GNDCPLG?") == "1000,10000,100000,1000000;" \
                                                                        "200.0000E+6;200.0000E+6;0"
    assert ask(s, "CONFIG:RF:BANDWIDTH?;:CONFIG:DIGITAL:MAXSAMPLERATE?") == "0.0E+0;0.0E+0"
    assert ask(s, "ALLEV?") == '0,"No events to report - queue empty"'


@pytest.mark.parametrize("personality, idn, channels", [
    ("mdo3000", "TEKTRONIX,MDO3012,X1,FV:1.0", 2), ("mdo3000", "TEKTRONIX,MDO3104,X1,FV:1.0", 4),
    ("mso4", "TEKTRONIX,MSO46,X1,FV:1.0", 4), ("tds2000", "TEKTRONIX,TDS 1002B,X1,FV:1.0", 2),
    ("tds2000", "TEKTRONIX,TDS 2024C,X1,FV:1.0", 4)])
def test_the_number_of_analog_channels_is_the_models_at_most_the_four_served(make_scope, personality, idn,
                                                                            channels):
    _scope, s, _ = make_scope(personality, idn=idn)
    assert ask(s, "CONFIGURATION:ANALOG:NUMCHANNELS?") == str(channels)


def test_the_bandwidth_follows_the_mdo3000_model_number_and_the_4_series_has_its_widest_option(make_scope):
    _scope, s, _ = make_scope("mdo3000", idn="TEKTRONIX,MDO3104,X1,FV:1.0")
    assert ask(s, "CONFIG:ANALOG:BANDWIDTH?;MAXSAMPLERATE?") == "1.0000E+9;5.0000E+9"
    _scope, s, _ = make_scope("mdo3000", idn="TEKTRONIX,MDO3034,X1,FV:1.0")
    assert ask(s, "CONFIG:ANALOG:BANDWIDTH?;MAXSAMPLERATE?") == "350.0000E+6;2.5000E+9"
    _scope, s, _ = make_scope("mso4")
    assert ask(s, "CONFIG:ANALOG:BANDWIDTH?") == "1.5000E+9"
    assert s.handle(b"CONFIG:ADVMATH?") == b"" and ask(s, "EVENT?") == "113"  # not in the 4 Series' tree


@pytest.mark.parametrize("personality", ["tds2000", "mdo3000"])
def test_the_clock_answers_and_takes_the_manuals_quoted_date_and_time(make_scope, personality):
    """DATE and TIME (miscellaneous group): "yyyy-mm-dd" and "hh:mm:ss", quoted both ways;
    a date not of the calendar is 222, another form 224; *RST leaves the clock."""
    import re

    _scope, s, _ = make_scope(personality)
    assert re.fullmatch(r'"\d{4}-\d{2}-\d{2}";"\d{2}:\d{2}:\d{2}"', ask(s, "DATE?;:TIME?"))
    s.handle(b'DATE "2031-02-28";:TIME "23:59:58";*RST')
    date, time = ask(s, "DATE?;:TIME?").split(";")
    assert date in ('"2031-02-28"', '"2031-03-01"') and time[:6] in ('"23:59', '"00:00')
    s.handle(b'DATE "2031-02-30"')
    assert ask(s, "EVENT?") == "222"
    for bad in (b"DATE 20310228", b'TIME "7:05"'):
        s.handle(bad)
        assert ask(s, "EVENT?") == "224", bad
