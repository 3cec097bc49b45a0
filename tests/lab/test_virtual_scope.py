"""The emulated scope's front panel: personalities' identities and preambles, settings
snapped to the model's steps and handed to the rig as scene overrides, *RST, channels on
and off, the events of refused settings, no file commands."""
import math

import numpy as np
import pytest

from instruments.errors import InstrumentError
from instruments.virtual_scope.instrument import VirtualScope
from lab.lab_scope import ask, fire, scene_scope


@pytest.mark.parametrize("personality, model, fields, yunit", [
    ("tds2000", "TDS 2024C", 16, '"Volts"'), ("mdo3000", "MDO3024", 22, '"V"'), ("mso4", "MSO44", 23, '"V"')])
def test_personalities_identify_and_answer_their_preamble(make_scope, personality, model, fields, yunit):
    _scope, s, _ = make_scope(personality)
    idn = ask(s, "*IDN?").split(",")
    assert idn[0] == "TEKTRONIX" and idn[1] == model and len(idn) == 4
    name = "WFMPre" if personality == "tds2000" else "WFMOutpre"
    assert len(ask(s, f"{name}?").split(";")) == fields
    assert ask(s, f"{name}:YUNIT?") == yunit
    s.handle(b"HEADER ON")
    reply = ask(s, f"{name}?")
    encoding = "BIN" if personality == "tds2000" else "BINARY"  # the TDS answers the short form (captured replies)
    assert reply.startswith(f":{name.upper()}:BYT_NR 1;BIT_NR 8;ENCDG {encoding};BN_FMT RI;BYT_OR MSB;")
    s.handle(b"VERBOSE OFF")
    assert ask(s, f"{name}:NR_PT?") == f":{'WFMP' if name == 'WFMPre' else 'WFMO'}:NR_P " + \
        ("2500" if personality == "tds2000" else "10000")


def test_tds_wfid_and_numbers_are_in_the_tek_form(make_scope):
    _scope, s, _ = make_scope("tds2000")
    fire(s)
    assert ask(s, "WFMPRE:WFID?") == '"Ch1, DC coupling, 5.0E-2 V/div, 5.0E-5 s/div, 2500 points, Sample mode"'
    assert ask(s, "WFMPRE:XINCR?;YMULT?;YZERO?") == "2.0E-7;2.0E-3;0.0E0"


def test_headers_spelled_between_short_and_long_as_tek_scripts_send_them(make_scope):
    """Tektronix's 5K/7K/70K fetch example sends DATA:SOUR and WFMO:NR_P?; a spelling
    past the long form or off it stays an undefined header."""
    _scope, s, _ = make_scope("mso4")
    s.handle(b"DATA:SOUR CH2;:HORIZ:RECORDL 1000")
    assert ask(s, "DATA:SOURC?;:WFMO:NR_P?;:HORIZONTAL:RECO?") == "CH2;1000;1000"
    s.handle(b"DATA:SOURCES CH1;:DATA:SOR CH1")
    assert ask(s, "DATA:SOURCE?") == "CH2"
    assert ask(s, "ALLEV?").count("113,") == 2


def test_idn_text_overrides_and_is_checked(make_scope):
    _scope, s, _ = make_scope("mso4", idn="TEKTRONIX,MSO46,X1,FV:1.0")
    assert ask(s, "*IDN?") == "TEKTRONIX,MSO46,X1,FV:1.0"
    with pytest.raises(InstrumentError, match="idn"):
        make_scope("mso4", idn="just a model")
    for personality, other in (("mso4", "TEKTRONIX,MSO58,X1,FV:1.0"), ("mdo3000", "TEKTRONIX,DPO4104,X1,FV:1.0"),
                               ("tds2000", "KEYSIGHT,TDS 2024C,X1,FV:1.0")):  # a model another manual describes
        with pytest.raises(InstrumentError, match="answers as the models of its manual"):
            make_scope(personality, idn=other)
    _scope, s, _ = make_scope("tds2000", idn="TEKTRONIX,TDS 1002B,C1,FV:v22.11")
    assert ask(s, "*IDN?") == "TEKTRONIX,TDS 1002B,C1,FV:v22.11"


def test_settings_snap_to_the_models_steps_and_become_overrides(make_scope):
    scope, s, _ = make_scope("mdo3000")
    assert scope.overrides() == {}
    s.handle(b"CH1:SCALE 30mV;:HOR:SCALE 3E-4;:HOR:RECORDLENGTH 120000;:TRIG:A:LEVEL 80mV;:CH2:BANDWIDTH FULL")
    assert ask(s, "CH1:SCALE?;:HOR:SCALE?;:HOR:RECO?;:HOR:SAMPLERATE?") == "20.0000E-3;400.0000E-6;100000;25.0000E+6"
    assert scope.overrides() == {"scope.channels.CH1.volts_per_div": "0.02 V", "scope.sample_interval": "4e-08 s",
                                 "scope.record_length": "100000", "scope.trigger.level": "0.08 V",
                                 "scope.channels.CH2.bandwidth": "full"}
    assert ask(s, "ALLEV?") == '0,"No events to report - queue empty"'


def test_tds_takes_2500_points_only_and_its_scene_snapping_is_an_override(make_scope):
    scope, s, _ = make_scope("tds2000", scene=scene_scope(20_000, 1e-7))
    assert scope.overrides() == {"scope.record_length": "2500", "scope.sample_interval": "1e-06 s"}
    s.handle(b"HOR:RECO 5000;:HOR:RECO 2500")
    assert ask(s, "HOR:RECO?;*ESR?;:EVQTY?") == "2500;144;1"
    assert ask(s, "ALLEV?") == '222,"Data out of range; HOR:RECO 5000: the tds2000 takes 2500"'


def test_record_length_is_bounded(make_scope):
    scope, s, _ = make_scope("mso4", max_record_length=100_000)
    s.handle(b"HOR:RECO 1E6")
    assert ask(s, "HOR:RECO?") == "10000" and ask(s, "EVENT?") == "221"
    scope, s, _ = make_scope("mso4", scene=scene_scope(500_000), max_record_length=100_000)
    assert scope.overrides()["scope.record_length"] == "100000"
    with pytest.raises(InstrumentError, match="max_record_length"):
        make_scope("mso4", max_record_length=500)


def test_rst_restores_the_scene_as_loaded(make_scope):
    scope, s, _ = make_scope("mdo3000")
    s.handle(b"CH1:SCA 1;POS 2;:SEL:CH3 ON;:DATA:ENC ASCII;:RIG:STR:VEL 1.2 m/s;:ACQ:MODE AVERAGE")
    assert len(scope.overrides()) > 5 and ask(s, "DATA:ENC?") == "ASCII"
    s.handle(b"*RST")
    assert scope.overrides() == {} and ask(s, "DATA:ENC?;:SEL?;:ACQ:MODE?") == "RIBINARY;1;1;0;0;SAMPLE"


def test_a_channel_switched_on_is_recorded_with_all_its_settings_and_one_off_is_refused(make_scope):
    scope, s, _source = make_scope("tds2000")
    s.handle(b"SELECT:CH3 ON;:CH3:SCALE 0.5")
    assert {k: v for k, v in scope.overrides().items() if ".CH3." in k} == {
        "scope.channels.CH3.volts_per_div": "0.5 V", "scope.channels.CH3.position": "0.0",
        "scope.channels.CH3.offset": "0.0 V", "scope.channels.CH3.coupling": "DC",
        "scope.channels.CH3.bandwidth": "20000000.0 Hz", "scope.channels.CH3.probe": "1.0"}
    s.handle(b"SELECT:CH2 OFF")
    fire(s)
    assert set(scope.acq.last.record.waveforms) == {"CH1", "CH2", "CH3"}  # the rig still records CH2
    assert ask(s, "*ESR?") == "128"
    assert s.handle(b"DATA:SOURCE CH2;:CURVE?") == b"#10\n" and ask(s, "WFMPRE?") == "1;8;BIN;RI;MSB"
    assert s.handle(b"WFMPRE:NR_PT?") == b""
    assert ask(s, "*ESR?") == "16"
    assert ask(s, "ALLEV?") == ('2244,"Source waveform is not active; CH2 is off; :CURVE?",'
                                '2244,"Source waveform is not active; CH2 is off; WFMPRE:NR_PT?"')
    s.handle(b"SELECT:CH1 OFF;CH3 OFF")
    assert ask(s, "SEL?") == "0;0;1;0" and ask(s, "EVENT?") == "221"  # one channel stays on


@pytest.mark.parametrize("command, code", [
    ("CH1:SCALE 20", -222), ("CH1:SCALE -1", -222), ("CH1:COUPLING GND", -221), ("CH1:POSITION 7", -222),
    ("TRIG:A:EDGE:SOURCE CH4", -221), ("TRIG:A:EDGE:COUPLING HFREJ", -221), ("ACQ:MODE PEAK", -221),
    ("ACQ:NUMAVG 1024", -222), ("DATA:WIDTH 4", -222), ("DATA:ENC FASTER", -224),
    ("CH5:SCALE 1", -113), ("FILESYSTEM:READFILE \"/etc/passwd\"", -113), ("SAVE:WAVEFORM CH1,\"a.isf\"", -113),
    ("SAVE:SETUP 1", -113), ("RIG:STR:VEL 5 furlongs", -224), ("RIG:SEED -1", -222)])
def test_refused_settings_queue_their_event_and_change_nothing(make_scope, command, code):
    scope, s, _ = make_scope("mdo3000")
    before = scope.overrides()
    assert s.handle(command.encode()) == b""
    assert ask(s, "EVENT?") == str(abs(code)) and scope.overrides() == before


def test_probe_gain_and_waveview_forms(make_scope):
    scope, s, _ = make_scope("mso4")
    s.handle(b"CH1:PROBE:GAIN 0.1;:DISPLAY:WAVEVIEW1:CH3:STATE ON")
    assert ask(s, "CH1:PROBE?;PROBE:GAIN?;:SEL:CH3?") == "10.0000;100.0000E-3;1"
    assert scope.overrides()["scope.channels.CH1.probe"] == "10.0"


def test_trigger_and_acquisition_settings(make_scope):
    scope, s, _ = make_scope("tds2000")
    s.handle(b"TRIG:MAIN:EDGE:SLOPE FALL;SOURCE CH2;:TRIG:MAIN:LEVEL -20mV;:ACQ:MODE AVE;NUMAVG 60;"
             b":HOR:MAIN:POSITION 0")
    assert ask(s, "TRIG:A:EDGE:SLOPE?;SOURCE?;:TRIG:A:LEVEL?;:ACQ:NUMAVG?;MODE?") == "FALL;CH2;-2.0E-2;64;AVERAGE"
    assert scope.overrides() == {"scope.trigger.slope": "falling", "scope.trigger.source": "CH2",
                                 "scope.trigger.level": "-0.02 V", "scope.mode": "average", "scope.averages": "64",
                                 "scope.trigger.pre_trigger": "0.5"}


def test_an_mdo_answers_the_preamble_of_a_channel_that_is_off_from_its_settings(make_scope):
    _scope, s, _ = make_scope("mdo3000")
    fire(s)
    s.handle(b"DATA:SOURCE CH4;:CH4:SCALE 0.5")
    assert ask(s, "WFMO:XUNIT?;YMULT?;NR_PT?") == '"s";20.0000E-3;10000'
    assert s.handle(b"CURVE?") == b"#10\n" and ask(s, "EVENT?") == "2244"


def test_data_start_and_stop_are_clamped_as_the_scopes_clamp_them(make_scope):
    _scope, s, _ = make_scope("mdo3000", max_record_length=100_000)
    s.handle(b"DAT:START 0;STOP 1e10")
    assert ask(s, "DAT:START?;STOP?;:WFMO:NR_P?") == "1;100000;10000"


def test_horizontal_mode_forms_are_the_same_settings(make_scope):
    """HORizontal:MODe:SCAle and :RECOrdlength are HORizontal:SCAle and :RECOrdlength; in MANual
    (4 Series manual, HORizontal:MODe: "when you change record length then the horizontal
    scale also changes") the sample rate of 10,000 points at 200 us/div, 5 MS/s, is kept."""
    _scope, s, _ = make_scope("mso4")
    s.handle(b"HOR:MODE MAN;:HOR:MODE:SCALE 1E-4;RECORDLENGTH 20000")
    assert ask(s, "HOR:SCALE?;RECO?;:HOR:MODE:SAMPLERATE?;:HOR:MODE?") == "400.0000E-6;20000;5.0000E+6;MANUAL"
    s.handle(b"HOR:MODE AUTO;:HOR:MODE:SCALE 1E-4;RECORDLENGTH 20000")  # AUTO: the scale kept
    assert ask(s, "HOR:SCALE?;RECO?;:HOR:MODE:SAMPLERATE?;:HOR:MODE?") == "100.0000E-6;20000;20.0000E+6;AUTO"


@pytest.mark.parametrize("slot", ["IMM", "MEAS3"])
def test_measurements_on_the_last_record(make_scope, slot):
    scope, s, _ = make_scope("mdo3000")
    s.handle(f"MEASU:{slot}:SOU1 CH1;TYP MAX".encode())
    assert ask(s, f"MEASU:{slot}:VAL?") == "99.1000E+36" and ask(s, "EVENT?") == "2225"
    fire(s)
    v = scope.acq.last.record["CH1"].volts()
    for kind, value in (("MAX", v.max()), ("MIN", v.min()), ("AMP", v.max() - v.min()), ("MEAN", v.mean()),
                        ("RMS", np.sqrt(np.mean(v * v)))):
        s.handle(f"MEASU:{slot}:TYP {kind}".encode())
        assert float(ask(s, f"MEASU:{slot}:VAL?")) == pytest.approx(value, rel=1e-12)
    s.handle(f"MEASU:{slot}:SOURCE CH2;:SEL:CH2 OFF".encode())
    assert s.handle(f"MEASU:{slot}:VAL?".encode()) == b"" and ask(s, "EVENT?") == "2244"
    assert v.max() == pytest.approx(0.2, abs=0.005)  # the pulse's peak, within 2 codes and the noise


@pytest.mark.parametrize("personality", ["mdo3000", "mso4"])
def test_a_measurements_second_source_is_its_own(make_scope, personality):
    """MEASUrement:MEAS<x>:SOUrce1 (MDO3000 manual): SOUrce1 is the source of single-channel
    measurements ("SOUrce is equivalent to SOURCE1"), SOUrce2 the waveform a delay or phase
    measurement goes "to": setting the second leaves the first, and the value is SOUrce1's."""
    scope, s, _ = make_scope(personality)
    fire(s)
    s.handle(b"MEASU:MEAS1:SOU1 CH1;:MEASU:MEAS1:SOU2 CH2;:MEASU:MEAS1:TYPE MAX;:MEASU:IMM:SOURCE2 CH2")
    assert ask(s, "MEASU:MEAS1:SOU1?;SOU2?;SOURCE?;:MEASU:IMM:SOU1?;SOU2?") == "CH1;CH2;CH1;CH1;CH2"
    value = float(ask(s, "MEASU:MEAS1:VAL?"))
    assert value == pytest.approx(scope.acq.last.record["CH1"].volts().max(), rel=1e-12)
    assert scope.acq.last.record["CH2"].volts().max() - value > 0.05  # not CH2's larger pulse (0.3 V)
    assert s.handle(b"MEASU:MEAS1:SOURCE3?") == b"" and ask(s, "EVENT?") == "113"


def test_a_scene_scope_no_model_can_take_is_refused():
    with pytest.raises(InstrumentError, match="personality"):
        VirtualScope(scene_scope(), lambda o, s: None, personality_name="tds9999")


@pytest.mark.parametrize("seed", [-1, 1.5, True, 2 ** 63])
def test_a_first_seed_that_is_no_seed_is_refused(seed):
    with pytest.raises(InstrumentError, match="seed"):
        VirtualScope(scene_scope(), lambda o, s: None, seed=seed)


def test_a_setting_given_one_value_too_many_queues_parameter_not_allowed(make_scope):
    """CH1:SCAle 0.1,0.2 had set 0.1 and said nothing of the 0.2: IEEE 488.2's -108
    (Parameter not allowed) is queued, naming what was not taken."""
    _scope, s, _ = make_scope("mdo3000")
    assert s.handle(b"CH1:SCALE 0.1,0.2") == b""
    assert ask(s, "EVENT?") == "108"
    s.handle(b"*CLS")
    s.handle(b"CH1:SCALE 0.1")
    assert ask(s, "EVENT?") == "0" and ask(s, "CH1:SCALE?") == "100.0000E-3"


def test_data_start_after_stop_sends_the_points_between_as_the_scopes_swap_them(make_scope):
    _scope, s, _ = make_scope("mdo3000")
    fire(s)
    s.handle(b"DATA:SOURCE CH1;:DATA:ENC RIB;WIDTH 1;:DAT:START 500;STOP 100")
    block = s.handle(b"CURVE?")
    digits = int(block[1:2])
    assert int(block[2:2 + digits]) == 401  # points 100 to 500, not the one point 500 alone


def test_a_measurement_of_a_clipped_source_gives_its_value_with_the_clipping_warning(make_scope):
    """A 0.2 V pulse at 10 mV/div runs off the 8-bit converter's top: the value (the rail)
    comes with event 548, Measurement warning, clipping positive, as the scopes give it."""
    scope, s, _ = make_scope("mdo3000")
    s.handle(b"CH1:SCALE 0.01;:MEASU:IMM:SOU1 CH1;TYP MAX")
    fire(s)
    assert scope.acq.last.record["CH1"].codes.max() == 127
    value = float(ask(s, "MEASU:IMM:VAL?"))
    assert value == pytest.approx(scope.acq.last.record["CH1"].volts().max(), rel=1e-12)
    assert ask(s, "EVENT?") == "548"


@pytest.mark.parametrize("personality", ["tds2000", "mdo3000", "mso4"])
def test_bit_nr_sets_the_bytes_a_point_is_sent_in(make_scope, personality):
    """WFMOutpre:BIT_Nr 16 (the 4/5/6 Series way to ask for 2 bytes a point) had been
    refused while the client went on reading 1-byte codes as 2-byte words: half the points,
    the volts off by about 170 times. It sets BYT_Nr with it, as the manuals couple them."""
    scope, s, _ = make_scope(personality)
    fire(s)
    pre = scope.personality.preamble
    s.handle(b"DATA:SOURCE CH1;:DATA:ENC RIB;:DATA:START 1;STOP 100")
    s.handle(f"{pre}:BIT_NR 16".encode())
    assert ask(s, f"{pre}:BYT_NR?;BIT_NR?") == "2;16" and ask(s, "EVENT?") == "0"
    block = s.handle(b"CURVE?")
    assert int(block[2:2 + int(block[1:2])]) == 200  # 100 points of 2 bytes
    s.handle(f"{pre}:BIT_NR 12".encode())
    assert ask(s, "EVENT?") == "222" and ask(s, f"{pre}:BYT_NR?") == "2"


def test_each_channel_keeps_its_own_trigger_level(make_scope):
    """TRIGger:A:LEVel:CH<x> (MSO/DPO4000, MDO3000, 4/5/6 Series manuals): each channel's
    own level, the trigger's where the channel is its source; switching the source takes
    that channel's level. It had been an undefined header (two public drivers use it)."""
    scope, s, _ = make_scope("mso4")
    s.handle(b"TRIG:A:EDGE:SOU CH1;:TRIG:A:LEV 0.03;:TRIG:A:LEV:CH2 0.1")
    assert ask(s, "EVENT?") == "0"
    assert ask(s, "TRIG:A:LEV?;LEV:CH1?;:TRIG:A:LEV:CH2?") == "30.0000E-3;30.0000E-3;100.0000E-3"
    s.handle(b"TRIG:A:EDGE:SOURCE CH2")
    assert ask(s, "TRIG:A:LEV?") == "100.0000E-3" and scope.overrides()["scope.trigger.level"] == "0.1 V"
    s.handle(b"TRIG:A:LEV:CH2 -0.02")
    assert scope.overrides()["scope.trigger.level"] == "-0.02 V"


def test_display_waveform_off_leaves_the_records_as_they_are(make_scope):
    scope, s, _ = make_scope("mdo3000")
    s.handle(b"DISPLAY:WAVEFORM OFF")
    assert ask(s, "DIS:WAVE?") == "0" and ask(s, "EVENT?") == "0"
    fire(s)
    assert scope.acq.last.record.triggered
    s.handle(b"*RST")
    assert ask(s, "DISPLAY:WAVEFORM?") == "1"


@pytest.mark.parametrize("personality", ["tds2000", "mso4"])
def test_set_query_restores_the_setup_it_describes(make_scope, personality):
    """SET? (and *LRN?) answer every setting as the commands that set it, headers on whatever
    HEADer says; sent back, they restore the set-up."""
    scope, s, _ = make_scope(personality)
    s.handle(b"HEADER OFF;VERBOSE OFF")
    setup = s.handle(b"SET?").rstrip(b"\n")
    assert setup.startswith(b":") and b":CH1:SCALE " in setup and s.handle(b"*LRN?").rstrip(b"\n") == setup
    before = scope.overrides()
    s.handle(b"CH1:SCALE 0.5;:CH2:COUPLING AC;:SELECT:CH4 ON;:TRIG:A:LEVEL 0.07;:DATA:ENC ASCII;WIDTH 2")
    assert scope.overrides() != before and ask(s, "*ESR?") == "128"  # power-on, read once
    s.handle(setup)
    assert scope.overrides() == before and ask(s, "DATA:ENC?;WIDTH?;*ESR?;:ALLEV?") == (
        'RIB;1;0;0,"No events to report - queue empty"')


@pytest.mark.parametrize("personality", ["tds2000", "mdo3000"])
def test_the_legacy_wfmpre_forms_of_the_tds_and_dpo4000_manuals(make_scope, personality):
    """WFMPre:CH<x>? gives channel x's waveform fields (WFID to YUNIT) whatever DATa:SOUrce
    is, WFMPre:CH<x>:<field>? one of them; the MDO3000 takes WFMPre? as its WFMOutpre?."""
    _scope, s, _ = make_scope(personality)
    fire(s)
    s.handle(b"DATA:SOURCE CH1")
    fields = ask(s, "WFMPRE:CH2?").split(";")
    assert len(fields) == 11 and fields[0].startswith('"Ch2, ') and fields[1] == ask(s, "WFMPRE:CH2:NR_PT?")
    assert ask(s, "WFMPRE:CH2:YMULT?") == ask(s, "DATA:SOURCE CH2;:WFMPRE:YMULT?") and ask(s, "EVENT?") == "0"
    if personality != "tds2000":
        assert ask(s, "WFMPRE?") == ask(s, "WFMOUTPRE?")


def test_the_4_series_adds_measurements_and_gives_the_current_acquisitions_results(make_scope):
    """MEASUrement:ADDMEAS switches on the first free slot (tm_devices' example's way);
    RESUlts:CURRentacq:MEAN? is the slot's value on the current record, PK2PK 0 and
    POPUlation 1 (one acquisition)."""
    scope, s, _ = make_scope("mso4")
    fire(s)
    s.handle(b"DATA:SOURCE CH2;:MEASUREMENT:ADDMEAS PK2PK")
    assert ask(s, "MEASU:MEAS1:TYPE?;SOURCE1?;STATE?") == "PK2PK;CH2;1"
    volts = scope.acq.last.record["CH2"].volts()
    mean = ask(s, "MEASUREMENT:MEAS1:RESULTS:CURRENTACQ:MEAN?")
    assert float(mean) == pytest.approx(volts.max() - volts.min(), rel=1e-4)
    assert ask(s, "MEASU:MEAS1:RESU:CURR:MAX?;MIN?;PK2PK?;POPU?;:EVENT?") == f"{mean};{mean};0.0E+0;1;0"


@pytest.mark.parametrize("personality", ["mdo3000", "mso4"])
def test_the_trigger_mode_and_the_b_trigger_are_kept_and_the_record_is_the_a_triggers(make_scope, personality):
    scope, s, _ = make_scope(personality)
    before = scope.overrides()
    s.handle(b"TRIG:A:MODE NORMAL;:TRIG:B:EDGE:SOURCE CH3;SLOPE FALL;:TRIG:B:LEVEL:CH3 TTL;:TRIG:B:STATE OFF")
    assert ask(s, "TRIG:A:MODE?;:TRIG:B:EDGE:SOURCE?;SLOPE?;:TRIG:B:LEVEL:CH3?;:TRIG:B:STATE?;:EVENT?") == (
        f"NORMAL;CH3;FALL;{scope.personality.number(1.4)};0;0")
    assert scope.overrides() == before  # nothing of the record changed
    s.handle(b"TRIG:B:STATE ON")
    assert ask(s, "EVENT?") == "221" and ask(s, "TRIG:B:STATE?") == "0"


@pytest.mark.parametrize("personality", ["mdo3000", "mso4"])
def test_display_settings_of_the_manual_are_kept_and_change_no_record(make_scope, personality):
    """The screen is not modelled: a display setting of the model's manual is taken as its
    syntax gives it and read back; a word outside it is 224; the record's settings stay."""
    scope, s, _ = make_scope(personality)
    before = scope.overrides()
    s.handle(b"DISPLAY:PERSISTENCE INFINITE;:DIS:PERS?")
    assert ask(s, "DIS:PERS?;:EVENT?") == "INFINITE;0"
    s.handle(b"DIS:PERS SOMETIMES")
    assert ask(s, "EVENT?") == "224" and ask(s, "DIS:PERS?") == "INFINITE"
    assert scope.overrides() == before


def test_timing_measurements_of_a_single_pulse_and_a_period_it_does_not_have(make_scope):
    """A Gaussian pulse a exp(-(t/w)^2): its width at the 50% mid reference is 2 w sqrt(ln 2)
    and its 10-90% rise w (sqrt(ln 10) - sqrt(ln(10/9))), each crossing placed to within a
    code over the pulse's slope there (the 8-bit converter's step in time; the noise is a
    tenth of a code) and a sample; a single pulse has no period: 9.91E37 and event 2202, as
    the scopes answer. The TDS2000 takes its manual's words (MINImum, CRMs, ...), not
    AMPlitude."""
    scope, s, _ = make_scope("mdo3000")
    fire(s)
    a, w = 0.2, 5e-5
    pre = scope.acq.last.record["CH1"].preamble
    dt, code = pre.x_increment, pre.y_multiplier

    def slope(f):  # |dv/dt| of the Gaussian where it is at f x its peak
        x = math.sqrt(math.log(1 / f))
        return a * 2 * x / w * f

    s.handle(b"MEASU:IMM:SOU1 CH1;TYP PWIDTH")
    assert float(ask(s, "MEASU:IMM:VAL?")) == pytest.approx(2 * w * math.sqrt(math.log(2)),
                                                            abs=2 * (code / slope(0.5) + dt))
    s.handle(b"MEASU:IMM:TYP RISE")
    rise = w * (math.sqrt(math.log(10)) - math.sqrt(math.log(10 / 9)))
    assert float(ask(s, "MEASU:IMM:VAL?")) == pytest.approx(rise, abs=code / slope(0.1) + code / slope(0.9) + 2 * dt)
    assert ask(s, "MEASU:IMM:UNITS?;:EVENT?") == '"s";0'
    s.handle(b"MEASU:IMM:TYP FREQ")
    assert ask(s, "MEASU:IMM:VAL?;:EVENT?;:MEASU:IMM:UNI?") == '99.1000E+36;2202;"Hz"'
    _scope, tds, _ = make_scope("tds2000")
    tds.handle(b"MEASU:IMM:TYP AMPLITUDE")
    assert ask(tds, "EVENT?") == "224"
    tds.handle(b"MEASU:IMM:TYP MINI;:MEASU:IMM:SOU CH2;:SEL:CH2 OFF")
    assert ask(tds, "MEASU:IMM:TYP?;VAL?;:EVENT?") == "MINIMUM;9.91E37;2225"  # the TDS manual: no time-out


def test_4_series_results_of_a_measurement_that_is_off_are_not_values(make_scope):
    _scope, s, _ = make_scope("mso4")
    fire(s)
    assert ask(s, "MEASU:LIST?") == "NONE"
    assert ask(s, "MEASU:MEAS1:RESU:CURR:MEAN?;:EVENT?") == "99.1000E+36;2225"
    s.handle(b"MEASUREMENT:ADDMEAS RISETIME")
    assert ask(s, "MEASU:LIST?;:MEASU:MEAS1:TYPE?;:EVENT?") == "MEAS1;RISETIME;0"
    assert 0 < float(ask(s, "MEASU:MEAS1:RESU:CURR:MEAN?")) < 1e-3


def test_noise_on_an_edge_is_no_cycle():
    """A single pulse in 8-bit codes with noise a tenth of a code: its rising edge crosses
    the 50% level back and forth between codes, which a crossing without hysteresis had
    counted as cycles (a 'frequency' set by the sample rate: 5 MHz at 10 samples' noise);
    with the scopes' hysteresis it has no period (2202) and its width is the pulse's."""
    from instruments.virtual_scope.measurements import MEASUREMENTS, NotMeasured

    dt, w = 1e-7, 5e-5
    t = np.arange(10_000) * dt
    rng = np.random.default_rng(1)
    code = 0.002
    v = np.round((0.2 * np.exp(-((t - 5e-4) / w) ** 2) + 0.1 * code * rng.standard_normal(t.size)) / code) * code
    with pytest.raises(NotMeasured) as no_period:
        MEASUREMENTS["FREQuency"](v, dt)
    assert no_period.value.code == 2202
    slope = 0.2 * 2 * math.sqrt(math.log(2)) / w * 0.5  # |dv/dt| at the half-amplitude crossings
    assert MEASUREMENTS["PWIdth"](v, dt) == pytest.approx(2 * w * math.sqrt(math.log(2)), abs=2 * (code / slope + dt))
