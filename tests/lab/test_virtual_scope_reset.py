"""*RST leaves the scope running (the manuals' default setup: ACQuire:STATE ON, STOPAfter
RUNSTop; ACQuire:STATE: "When state is set to ON or RUN, a new acquisition will be
started"), waiting for an impact: the rig strikes on its own (on-arm, every=S) only once a
client arms the scope, so that no seed is taken while a client configures it and the k-th
shot fired keeps seed N + k - 1 (acquisition.py)."""
import time

import pytest

from lab.lab_scope import ask, fire


@pytest.mark.parametrize("personality", ["tds2000", "mdo3000", "mso4"])
def test_after_rst_the_scope_runs_idle_and_takes_no_seed_until_a_client_arms_it(make_scope, personality):
    scope, s, source = make_scope(personality, seed=50)
    s.handle(b"ACQ:STOPAFTER SEQUENCE;STATE OFF")
    s.handle(b"*RST")
    assert ask(s, "ACQ:STATE?;STOPAFTER?;:BUSY?;:TRIG:STATE?;*OPC?") == "1;RUNSTOP;0;READY;1"
    time.sleep(0.3)  # on-arm: the rig at rest strikes nothing for a scope nobody armed
    assert source.calls == [] and ask(s, "RIG:SEED?;:ACQ:NUMACQ?") == "50;0"
    s.handle(b"CH1:SCALE 0.1;:ACQ:STOPAFTER SEQUENCE")  # configuring: still nothing pending, no shot
    assert ask(s, "BUSY?;:ACQ:STATE?") == "0;1" and source.calls == []
    fire(s)  # STATE ON on the running scope: a new acquisition, the first shot at the first seed
    assert [seed for _, seed in source.calls] == [50]
    assert source.calls[0][0] == {"scope.channels.CH1.volts_per_div": "0.1 V"}
    assert ask(s, "ACQ:STATE?;:BUSY?") == "0;0"


def test_a_rig_fire_on_the_idle_scope_is_one_record_and_it_waits_again(make_scope):
    """RIG:FIRE on the running idle scope: one shot (the next seed), the scope still running
    and waiting (no shots back to back); with STOPAfter SEQuence set meanwhile, the record
    ends the sequence."""
    scope, s, source = make_scope("mso4", seed=3)
    s.handle(b"*RST;:RIG:FIRE")
    assert ask(s, "*OPC?") == "1"
    time.sleep(0.2)
    assert [seed for _, seed in source.calls] == [3] and ask(s, "ACQ:STATE?;NUMACQ?;:BUSY?") == "1;1;0"
    s.handle(b"ACQ:STOPAFTER SEQUENCE;:RIG:FIRE")
    assert ask(s, "*OPC?") == "1" and ask(s, "ACQ:STATE?;NUMACQ?") == "0;2"
    assert [seed for _, seed in source.calls] == [3, 4]


def test_rst_ends_run_mode_shots_back_to_back_and_the_scope_keeps_running(make_scope):
    scope, s, source = make_scope("tds2000")
    s.handle(b"ACQ:STOPAFTER RUNSTOP;STATE RUN")
    deadline = time.monotonic() + 30
    while scope.acq.count < 2:  # a client polling: each message after a record brings the next impact
        assert time.monotonic() < deadline
        ask(s, "ACQ:NUMACQ?")
        time.sleep(0.005)
    s.handle(b"*RST")
    while scope.acq.busy:
        time.sleep(0.005)
    calls = len(source.calls)
    time.sleep(0.2)
    assert len(source.calls) == calls and ask(s, "ACQ:STATE?;:BUSY?") == "1;0"
    assert [seed for _, seed in source.calls] == list(range(calls))


def test_every_period_the_ticks_pass_by_the_idle_scope_until_it_is_armed(make_scope):
    scope, s, source = make_scope("tds2000", fire_period_s=0.1)
    s.handle(b"*RST")
    time.sleep(0.35)  # three ticks: the scope runs, nobody armed it
    assert source.calls == [] and ask(s, "ACQ:STATE?") == "1"
    s.handle(b"ACQ:STOPA SEQ;STATE ON")
    assert ask(s, "*OPC?") == "1" and len(source.calls) == 1 and ask(s, "ACQ:STATE?") == "0"


@pytest.mark.parametrize("command", [b"TRIGGER FORCE", b"*TRG", None])
def test_a_forced_trigger_on_a_stopped_scope_is_ignored(make_scope, command):
    """TRIGger FORCe (and *TRG, the transports' device trigger): "If TRIGger:STATE is set
    to READy, the acquisition will complete. Otherwise, this command will be ignored": on a
    stopped scope (TRIGger:STATE? SAVE) no shot, no seed, no event; on the running scope
    one record, taken as AUTO takes it."""
    scope, s, source = make_scope("mso4", seed=8)
    fire(s)  # a single sequence: stopped after it
    assert ask(s, "ACQ:STATE?;:TRIG:STATE?") == "0;SAVE"
    s.handle(command) if command else s.trigger()
    assert ask(s, "*OPC?") == "1" and len(source.calls) == 1
    assert ask(s, "RIG:SEED?;:ACQ:NUMACQ?;:ALLEV?") == '9;1;0,"No events to report - queue empty"'
    s.handle(b"*RST")
    s.handle(command) if command else s.trigger()
    assert ask(s, "*OPC?") == "1" and [seed for _, seed in source.calls] == [8, 9]
    assert scope.acq.last.overrides["scope.trigger.mode"] == "auto" and ask(s, "ACQ:STATE?") == "1"


def test_power_on_is_the_reset_state_and_the_first_acquisition_leaves_it_waiting(make_scope):
    scope, s, source = make_scope("tds2000", seed=2)
    assert ask(s, "ACQ:STATE?;STOPAFTER?;:BUSY?") == "1;RUNSTOP;0"
    scope.acq.first_acquisition()
    time.sleep(0.2)
    assert [seed for _, seed in source.calls] == [2] and ask(s, "ACQ:STATE?;NUMACQ?;:BUSY?") == "1;1;0"


def test_on_arm_in_run_mode_the_rig_strikes_again_when_a_client_next_talks_to_the_scope(make_scope):
    """--fire on-arm in run mode: one impact when armed, then one more at the first client
    message after each record; a client that leaves the scope running and goes (a program
    restoring the state it found) leaves no rig firing records nobody asks for."""
    scope, s, source = make_scope("mso4", seed=5)
    s.handle(b"ACQ:STOPAFTER RUNSTOP;STATE RUN")
    deadline = time.monotonic() + 30
    while scope.acq.count < 1 or scope.acq.busy:
        assert time.monotonic() < deadline
        time.sleep(0.005)
    time.sleep(0.3)
    assert len(source.calls) == 1 and ask(s, "ACQ:STATE?;:BUSY?") == "1;0"  # running, the rig at rest
    while scope.acq.count < 2 or scope.acq.busy:  # that query was a message: the next impact
        assert time.monotonic() < deadline
        time.sleep(0.005)
    time.sleep(0.3)
    assert [seed for _, seed in source.calls] == [5, 6] and scope.acq.count == 2
