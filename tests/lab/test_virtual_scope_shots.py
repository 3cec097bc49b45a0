"""Shots: single sequence, run mode, forced shots, seeds N + k - 1, records bit-identical to
an acquisition with the same settings, *OPC? waiting, other sessions answered during a
shot, settings changed during a shot applying to the next, the RIG: subsystem."""
import threading
import time

import numpy as np
import pytest

from instruments.devices.oscilloscope import ChannelSettings, Oscilloscope, Timebase, Trigger
from instruments.errors import InstrumentError
from lab.lab_scope import H, ask, fire, pulse


def wait_for(predicate, timeout=30.0):
    end = time.monotonic() + timeout
    while not predicate():
        assert time.monotonic() < end, "timed out"
        time.sleep(0.005)


def test_kth_shot_uses_seed_n_plus_k_minus_1_and_equals_an_acquisition_with_the_same_settings(make_scope):
    shots = []
    _scope, s, source = make_scope("tds2000", seed=40, on_shot=shots.append)
    s.handle(b"CH1:SCALE 20mV;:HOR:SCALE 1E-4;:TRIG:A:LEVEL 0.03")
    for _ in range(3):
        fire(s)
    assert [seed for _, seed in source.calls] == [40, 41, 42] and [sh.seed for sh in shots] == [40, 41, 42]
    assert ask(s, "ACQ:NUMACQ?") == "3"
    expected = Oscilloscope(channels={"CH1": ChannelSettings(0.02, -1.0, bandwidth=None),
                                      "CH2": ChannelSettings(0.1, bandwidth=20e6)},
                            timebase=Timebase(4e-7, 2500), trigger=Trigger("CH1", 0.03, "rising", 0.2))
    record = expected.acquire({"CH1": pulse(), "CH2": pulse(0.3)}, H, np.random.default_rng(42))
    got = shots[-1].record
    for ch in ("CH1", "CH2"):
        assert np.array_equal(got[ch].codes, record[ch].codes)
        assert got[ch].preamble.x_zero == record[ch].preamble.x_zero
    assert shots[-1].overrides == {"scope.channels.CH1.volts_per_div": "0.02 V", "scope.sample_interval": "4e-07 s",
                                   "scope.trigger.level": "0.03 V"}


def test_opc_waits_for_the_record_and_busy_reads_1_from_another_session_meanwhile(make_scope):
    scope, s, source = make_scope("mdo3000", seed=5)
    other = scope.open_session("other")
    source.gate = threading.Event()
    s.handle(b"ACQ:STOPAFTER SEQUENCE;STATE RUN")
    answer = []
    waiter = threading.Thread(target=lambda: answer.append(s.handle(b"*OPC?")))
    waiter.start()
    wait_for(lambda: source.calls)
    assert ask(other, "BUSY?;:ACQ:STATE?;*IDN?").startswith("1;1;TEKTRONIX,MDO3024")
    other.handle(b"CH1:SCALE 0.1")  # applies to the next shot
    time.sleep(0.05)
    assert waiter.is_alive() and answer == []
    source.gate.set()
    waiter.join(30)
    assert answer == [b"1\n"] and ask(other, "BUSY?;:ACQ:STATE?") == "0;0"
    assert source.calls[0][0] == {}
    fire(s)
    assert source.calls[1] == ({"scope.channels.CH1.volts_per_div": "0.1 V"}, 6)


def test_run_mode_fires_again_at_each_poll_until_stopped(make_scope):
    """Run mode, --fire on-arm: a record, then the next impact at the client's next message
    (acquisition.py): a client polling gets records one after the other until it stops."""
    scope, s, source = make_scope("tds2000")
    s.handle(b"ACQ:STOPAFTER RUNSTOP;STATE ON")
    assert ask(s, "*OPC?") == "1"  # run mode has nothing pending
    wait_for(lambda: ask(s, "ACQ:NUMACQ?") and scope.acq.count >= 3)
    s.handle(b"ACQ:STATE STOP")
    wait_for(lambda: not scope.acq.busy)
    count = scope.acq.count
    time.sleep(0.2)
    assert scope.acq.count == count and ask(s, "ACQ:STATE?;:TRIGGER:STATE?") == "0;SAVE"
    assert [seed for _, seed in source.calls] == list(range(count))


@pytest.mark.parametrize("command", ["TRIGGER FORCE", "RIG:FIRE", "*TRG"])
def test_forced_shots_fire_once(make_scope, command):
    _scope, s, source = make_scope("tds2000", seed=9)
    s.handle(command.encode())
    assert ask(s, "*OPC?") == "1" and ask(s, "ACQ:NUMACQ?") == "1" and source.calls[0][1] == 9


def test_opc_command_sets_the_esr_bit_when_the_record_is_in(make_scope):
    scope, s, source = make_scope("tds2000")
    source.gate = threading.Event()
    s.handle(b"*ESR?;:ACQ:STOPA SEQ;STATE 1;*OPC")
    assert ask(s, "*ESR?") == "0"
    source.gate.set()
    wait_for(lambda: scope.acq.count == 1)
    assert ask(s, "*ESR?") == "1"


def test_device_clear_interrupts_a_waiting_query(make_scope):
    _scope, s, source = make_scope("tds2000")
    source.gate = threading.Event()
    s.handle(b"ACQ:STOPA SEQ;STATE 1")
    answer = []
    waiter = threading.Thread(target=lambda: answer.append(s.handle(b"*OPC?")))
    waiter.start()
    wait_for(lambda: source.calls)
    s.device_clear()
    waiter.join(30)
    source.gate.set()
    assert answer == [b""] and ask(s, "EVENT?") == "410"


def test_the_rigs_refusal_is_an_event_and_takes_no_seed(make_scope):
    scope, s, _source = make_scope("mso4", seed=3)
    s.handle(b"HOR:SCALE 1E-3")  # the model takes 10 ms; the synthetic input stops at 8 ms
    s.handle(b"RIG:FIRE;*OPC?")
    assert ask(s, "EVENT?") == "200" and scope.acq.last is None
    msg = ask(s, "RIG:SEED?")
    assert msg == "3"
    s.handle(b"HOR:SCALE 2E-4")
    fire(s)
    assert scope.acq.last.seed == 3


def test_rig_commands_take_quantities_checked_by_the_injected_validator(make_scope):
    scope, s, source = make_scope("tds2000", seed=1)
    s.handle(b'RIG:STRIKER:VELOCITY 1.2 m/s;:RIG:MAGNET:FORCE "2.38 N";POSITION 5 mm;:RIG:SEED 100')
    assert ask(s, "EVENT?") == "224"  # 5 mm: the validator wants m
    assert ask(s, "RIG:STR:VEL?;:RIG:MAG:FORC?;POS?;:RIG:SEED?;:RIG:SCENE?") == \
        '"1.2 m/s";"2.38 N";"not set in the scene";100;"synthetic"'
    fire(s)
    overrides, seed = source.calls[-1]
    assert seed == 100 and overrides == {"striker.velocity": "1.2 m/s", "magnet.force": "2.38 N"}
    assert ask(s, "RIG:OVERRIDES?") == '"striker.velocity=1.2 m/s,magnet.force=2.38 N"'
    peak = scope.acq.last.record["CH1"].volts().max()
    assert peak == pytest.approx(0.2 * 1.2 / 0.9, abs=0.005)  # the pulse scales with the velocity


def test_the_rig_port_shares_the_instruments_state(make_scope):
    scope, s, source = make_scope("tds2000", seed=1)
    rig = scope.rig_port().open_session("rig")
    assert rig.handle(b"CH1:SCALE 1") == b"" and ask(rig, "EVENT?") == "113"  # no scope commands there
    rig.handle(b"RIG:STR:VEL 0.45 m/s;:RIG:FIRE")
    assert ask(rig, "*OPC?") == "1" and ask(s, "ACQ:NUMACQ?") == "1"
    assert source.calls[0][0] == {"striker.velocity": "0.45 m/s"}


def test_limits_of_messages_and_replies(make_scope):
    _scope, s, _ = make_scope("tds2000", max_message_bytes=100, max_reply_bytes=1000)
    assert s.handle(b"*IDN?;" * 30) == b"" and ask(s, "EVENT?") == "363"
    s.overflow(10_000)
    assert ask(s, "EVENT?") == "363"
    fire(s)
    assert s.handle(b"DATA:ENC ASCII;:CURVE?") == b"" and ask(s, "EVENT?") == "350"
    s.handle(b"DATA:ENC RIB;START 1;STOP 500")
    assert len(s.handle(b"CURVE?")) == 506


def test_on_command_an_armed_scope_waits_for_a_fire_command(make_scope):
    scope, s, source = make_scope("tds2000", on_command=True)
    s.handle(b"ACQ:STOPA SEQ;STATE ON")
    time.sleep(0.2)
    assert source.calls == [] and ask(s, "BUSY?;:ACQ:STATE?") == "1;1"
    rig = scope.rig_port().open_session("rig")
    rig.handle(b"RIG:FIRE")
    assert ask(s, "*OPC?") == "1" and ask(s, "BUSY?;:ACQ:STATE?;NUMACQ?") == "0;0;1"


def test_every_period_an_armed_scope_fires_at_the_ticks(make_scope):
    _scope, s, source = make_scope("tds2000", fire_period_s=0.3)
    time.sleep(0.35)
    assert source.calls == []  # not armed: the ticks pass by
    start = time.monotonic()
    s.handle(b"ACQ:STOPA SEQ;STATE ON")
    assert ask(s, "*OPC?") == "1"
    waited = time.monotonic() - start
    assert 0.1 < waited < 0.6 and len(source.calls) == 1  # the next tick, 0.6 s after the start
    s.handle(b"ACQ:STOPA RUNSTOP;STATE ON")
    time.sleep(1.0)
    s.handle(b"ACQ:STATE OFF")
    assert 2 <= len(source.calls) - 1 <= 4  # about one shot per 0.3 s


def test_a_period_must_be_positive(make_scope):
    with pytest.raises(InstrumentError, match="fire_period_s"):
        make_scope("tds2000", fire_period_s=0.0)


def test_sixteen_clients_at_once_during_shots(make_scope):
    scope, s, source = make_scope("mdo3000", seed=0)
    s.handle(b"ACQ:STOPAFTER RUNSTOP;STATE RUN")  # shots back to back meanwhile
    failures = []

    def client(k):
        session = scope.open_session(f"client {k}")
        try:
            for i in range(40):
                session.handle(f"CH{k % 4 + 1}:POSITION {i % 5 - 2}".encode())
                reply = session.handle(b"*IDN?;:DATA:WIDTH?;:BUSY?;:HOR:RECO?")
                idn, width, busy, length = reply.decode().rstrip("\n").split(";")
                if not (idn.startswith("TEKTRONIX,MDO3024") and width == "1" and busy in "01" and length == "10000"):
                    failures.append(reply)
        except Exception as e:  # noqa: BLE001 - collected and asserted below
            failures.append(repr(e))
        finally:
            session.close()

    threads = [threading.Thread(target=client, args=(k,)) for k in range(16)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(60)
    s.handle(b"ACQ:STATE STOP")
    assert failures == [] and scope.acq.count >= 1
    assert [seed for _, seed in source.calls] == list(range(len(source.calls)))
    assert ask(s, "ALLEV?") == '0,"No events to report - queue empty"'


def test_the_first_acquisition_is_the_first_shot_and_what_curve_answers_before_any_client_fires(make_scope):
    scope, s, source = make_scope("mso4", seed=7)
    kept = []
    scope.acq.on_shot = kept.append
    assert s.handle(b"CURVE?") == b"#10\n"  # before it: an execution error, no record yet, answered at once
    assert ask(s, "EVENT?") == "200"
    shot = scope.acq.first_acquisition()
    assert (shot.seed, scope.acq.count, kept) == (7, 1, [shot])
    assert source.calls == [(scope.overrides(), 7)]  # the settings the scope starts with
    # the scope runs from power-on, as a real one does (the manuals' default setup), waiting idle for the next
    # impact after its first acquisition (acquisition.py): ACQuire:STATE? 1, nothing pending
    assert ask(s, "RIG:SEED?;:ACQUIRE:NUMACQ?;:ACQUIRE:STATE?;:BUSY?") == "8;1;1;0"
    s.handle(b"DATA:SOURCE CH1;:DATA:ENCDG ASCII;:DATA:START 1;:DATA:STOP 100000")
    codes = np.array(ask(s, "CURVE?").split(","), dtype=int)
    assert np.array_equal(codes, shot.record["CH1"].codes) and ask(s, "EVENT?") == "0"
    fire(s)
    assert scope.acq.last.seed == 8


def test_a_first_acquisition_the_rig_refuses_is_one_line_and_takes_no_seed():
    from instruments.virtual_scope.instrument import VirtualScope
    from lab.lab_scope import scene_scope

    def refusing(overrides, seed):
        raise InstrumentError("striker.velocity = '9 m/s': at most 5 m/s")

    scope = VirtualScope(scene_scope(), refusing, personality_name="mso4", seed=4)
    try:
        with pytest.raises(InstrumentError, match=r"^the first shot, at seed 4: striker.velocity = '9 m/s'"):
            scope.acq.first_acquisition()
        assert scope.acq.next_seed == 4 and scope.acq.last is None and scope.acq.count == 0
    finally:
        scope.close()


def test_a_shot_the_rig_refuses_leaves_no_record_that_could_pass_for_it(make_scope):
    """A refused shot drops the last record: CURVe? names the refusal instead of sending the
    earlier shot's codes; the refusal is whole in the queue; a good shot brings records back."""
    scope, s, source = make_scope()
    fire(s)
    assert scope.acq.last is not None
    reason = "striker.velocity = '500 m/s': " + "the striker would press far into the top bead; " * 8
    good = source.record
    source.record = lambda overrides, seed: (_ for _ in ()).throw(InstrumentError(reason))
    s.handle(b"*CLS")
    fire(s)
    assert s.handle(b"CURVe?") == b"#10\n"  # no record: an empty block, at once
    events = ask(s, "ALLEv?")
    assert reason.strip() in events and events.count("200,\"Execution error") == 2  # the refusal (whole), then CURVe?'s
    assert "the last shot failed" in events
    source.record = good
    fire(s)
    assert s.handle(b"DATa:ENCdg ASCii;:CURVe?").count(b",") > 100


def test_rig_settings_read_back_the_scenes_value_until_set(make_scope):
    scope, s, _ = make_scope(rig_scene={"striker.velocity": "0.89 m/s"})
    assert ask(s, "RIG:STRiker:VELocity?") == '"0.89 m/s"'
    assert ask(s, "RIG:MAGnet:POSition?") == '"not set in the scene"'
    s.handle(b"RIG:STR:VEL 0.95 m/s")
    assert ask(s, "RIG:STRIKER:VELOCITY?") == '"0.95 m/s"'


@pytest.mark.parametrize("personality", ["tds2000", "mso4"])
def test_auto_takes_a_record_without_a_trigger_and_the_trigger_state_says_auto(make_scope, personality):
    """TRIGger:A:MODe AUTO: a rising edge at -0.4 V on a pulse resting at 0 V never fires,
    yet each shot gives a record (its settings' length and interval, flagged untriggered)
    and no event; while the scope runs so, TRIGger:STATE? is AUTO, stopped SAVE. NORMal:
    no new record, the armed scope waits for a trigger (test_virtual_scope_normal.py)."""
    scope, s, source = make_scope(personality, seed=4)
    s.handle(b"TRIG:A:MODE AUTO;:TRIG:A:EDGE:SLOPE RISE;:TRIG:A:LEVEL -0.4")
    assert scope.overrides()["scope.trigger.mode"] == "auto" and ask(s, "TRIG:A:MODE?") == "AUTO"
    fire(s)
    record = scope.acq.last.record
    n = scope.settings["scope.record_length"]
    assert not record.triggered and record["CH1"].codes.size == n and ask(s, "*ESR?;:ALLEV?").endswith(
        '0,"No events to report - queue empty"')
    assert record["CH1"].preamble.x_increment == scope.settings["scope.sample_interval"]
    assert np.array_equal(record["CH1"].codes, source.record(*source.calls[-1])["CH1"].codes)
    assert ask(s, "TRIG:STATE?") == "SAVE"
    s.handle(b"ACQ:STOPAFTER RUNSTOP;STATE RUN")
    wait_for(lambda: ask(s, "ACQ:NUMACQ?") and scope.acq.count >= 3)  # a client polling: a shot per poll
    assert ask(s, "TRIG:STATE?") == "AUTO"
    s.handle(b"ACQ:STATE STOP")
    wait_for(lambda: not scope.acq.busy)
    assert ask(s, "TRIG:STATE?") == "SAVE"
    s.handle(b"TRIG:A:MODE NORMAL")
    assert "scope.trigger.mode" not in scope.overrides()  # the scene's mode
    kept, calls = scope.acq.last, len(source.calls)
    s.handle(b"ACQ:STOPAFTER SEQUENCE;STATE ON")
    wait_for(lambda: len(source.calls) == calls + 1 and not scope.acq.busy)
    assert ask(s, "BUSY?;:TRIG:STATE?;:ALLEV?") == '1;READY;0,"No events to report - queue empty"'
    assert scope.acq.last is kept
    s.handle(b"ACQ:STATE OFF")
