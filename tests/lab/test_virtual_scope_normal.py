"""NORMal trigger mode (the manuals, TRIGger:A:MODe: "NORMal waits for a valid trigger
event"): a shot that does not trigger leaves the armed scope armed, with no new record (the
last one kept), ACQuire:STATE? 1, TRIGger:STATE? READY, BUSY? 1 and *OPC? waiting in a single
sequence, until TRIGger FORCe ("creates a trigger event. If TRIGger:STATE is set to READy,
the acquisition will complete": the record AUTO takes), ACQuire:STATE OFF, a shot that
triggers, or for the waiting query a device clear. A rising edge at -0.4 V on a pulse resting
at 0 V never fires (lab_scope.py's synthetic shots)."""
import threading
import time

import numpy as np
import pytest

from lab.lab_scope import ask, fire

NEVER = (b"TRIGger:A:MODe NORMal;:TRIGger:A:EDGE:SLOpe RISe;:TRIGger:A:LEVel:CH1 -0.4;"
         b":ACQuire:STOPAfter SEQuence;:ACQuire:STATE ON")
EMPTY = '0,"No events to report - queue empty"'


def wait_for(predicate, timeout=30.0):
    end = time.monotonic() + timeout
    while not predicate():
        assert time.monotonic() < end, "timed out"
        time.sleep(0.005)


def asked_meanwhile(session, query: bytes) -> tuple:
    """(the thread asking ``query`` on ``session``, the list its reply goes to)."""
    answer: list = []
    thread = threading.Thread(target=lambda: answer.append(session.handle(query)))
    thread.start()
    return thread, answer


@pytest.mark.parametrize("personality", ["tds2000", "mso4"])
def test_an_armed_scope_that_does_not_trigger_waits_and_a_forced_trigger_completes_it(make_scope, personality):
    scope, s, source = make_scope(personality, seed=4)
    fire(s)
    kept = scope.acq.last
    s.handle(NEVER)
    wait_for(lambda: len(source.calls) == 2 and not scope.acq.busy)  # the impact, seed 5: no trigger
    assert ask(s, "ACQuire:STATE?;:TRIGger:STATE?;:BUSY?;:ACQuire:NUMACq?") == "1;READY;1;1"
    assert scope.acq.last is kept and ask(s, "ALLEV?") == EMPTY  # no record, no event: it waits
    s.handle(b"DATA:SOURCE CH1;:DATA:ENCDG ASCII;:DATA:START 1;:DATA:STOP 100000")
    assert np.array_equal(np.array(ask(s, "CURVE?").split(","), dtype=int), kept.record["CH1"].codes)
    waiter, answer = asked_meanwhile(s, b"*OPC?")
    time.sleep(0.3)
    assert waiter.is_alive() and answer == [] and len(source.calls) == 2  # on-arm: the impact is spent
    scope.open_session("other").handle(b"TRIGGER FORCE")
    waiter.join(30)
    assert answer == [b"1\n"] and ask(s, "ACQuire:STATE?;:TRIGger:STATE?;:BUSY?;:ACQuire:NUMACq?") == "0;SAVE;0;2"
    forced = scope.acq.last
    assert forced.seed == 6 and forced.overrides["scope.trigger.mode"] == "auto"  # the record AUTO takes
    assert not forced.record.triggered and forced.record.reason.startswith("auto-triggered")
    assert np.array_equal(forced.record["CH1"].codes, source.record(forced.overrides, 6)["CH1"].codes)
    assert ask(s, "ALLEV?") == EMPTY


def test_acquire_state_off_ends_the_wait_and_a_device_clear_ends_the_query_only(make_scope):
    scope, s, source = make_scope("mso4")
    s.handle(NEVER)
    wait_for(lambda: source.calls and not scope.acq.busy)
    waiter, answer = asked_meanwhile(s, b"*OPC?")
    time.sleep(0.1)
    s.device_clear()
    waiter.join(30)
    assert answer == [b""] and ask(s, "EVENT?") == "410" and ask(s, "ACQ:STATE?;:BUSY?") == "1;1"
    waiter, answer = asked_meanwhile(s, b"*OPC?")
    time.sleep(0.1)
    scope.open_session("other").handle(b"ACQUIRE:STATE OFF")
    waiter.join(30)
    assert answer == [b"1\n"] and ask(s, "ACQ:STATE?;:TRIG:STATE?;:BUSY?") == "0;SAVE;0"
    assert scope.acq.last is None and len(source.calls) == 1


def test_on_arm_one_impact_per_arming_and_rig_fire_is_another_impact(make_scope):
    """The spent impact is not fired again (no shots in a loop): re-arming fires one, and so
    does RIG:FIRE, each in NORMal (still waiting), each at the next seed."""
    scope, s, source = make_scope("mso4", seed=20)
    s.handle(NEVER)
    wait_for(lambda: source.calls and not scope.acq.busy)
    time.sleep(0.2)
    assert len(source.calls) == 1
    s.handle(b"ACQ:STATE OFF;STATE ON")
    wait_for(lambda: len(source.calls) == 2 and not scope.acq.busy)
    s.handle(b"RIG:FIRE")
    wait_for(lambda: len(source.calls) == 3 and not scope.acq.busy)
    assert [seed for _, seed in source.calls] == [20, 21, 22] and ask(s, "BUSY?;:ACQ:STATE?") == "1;1"
    assert all("scope.trigger.mode" not in overrides for overrides, _ in source.calls)  # NORMal, the scene's


def test_every_period_a_waiting_scope_takes_the_next_impact_that_triggers(make_scope):
    scope, s, source = make_scope("tds2000", fire_period_s=0.15)
    s.handle(NEVER)
    wait_for(lambda: len(source.calls) >= 2)  # an impact each tick, none triggering
    assert scope.acq.last is None and ask(s, "BUSY?;:ACQ:STATE?") == "1;1"
    s.handle(b"TRIGGER:A:LEVEL 0.05")  # the next impact crosses it
    assert ask(s, "*OPC?") == "1" and scope.acq.last.record.triggered
    assert ask(s, "ACQ:STATE?;:BUSY?;:ALLEV?") == f"0;0;{EMPTY}"


def test_rig_fire_on_a_stopped_scope_that_does_not_trigger_says_so_and_keeps_the_record(make_scope):
    scope, s, _ = make_scope("mdo3000", seed=1)
    fire(s)
    kept = scope.acq.last
    s.handle(b"TRIG:A:LEVEL -0.4;:RIG:FIRE")
    assert ask(s, "*OPC?") == "1" and scope.acq.last is kept and ask(s, "ACQ:STATE?;:RIG:SEED?") == "0;3"
    events = ask(s, "ALLEV?")
    assert events.startswith('200,"Execution error; the shot of seed 2 did not trigger: no rising crossing of -0.4 V')
    assert "the last one kept" in events


def test_a_curve_stream_in_normal_waits_for_a_trigger(make_scope):
    """CURVEStream? sends each acquisition's curve: an impact that does not trigger sends
    nothing (the stream waits), a device trigger (*TRG's, forced) sends the record AUTO takes."""
    scope, s, source = make_scope("mso4", seed=30)
    s.handle(b"TRIG:A:LEVEL -0.4;:DATA:SOURCE CH1;:DATA:ENCDG ASCII;:DATA:START 1;:DATA:STOP 100000;"
             b":CURVESTREAM?")
    assert s.next_reply(0.3) == b"" and len(source.calls) == 1 and scope.acq.last is None
    scope.open_session("other").trigger()
    block = s.next_reply(30)
    assert block and source.calls[-1][1] == 31
    expected = source.record(*source.calls[-1])["CH1"].codes
    assert np.array_equal(np.array(block.decode().strip().split(","), dtype=int), expected)
