"""A record for every horizontal setting the model offers (the scene's rig behind the scope):
a record lasting longer than the scene's solve, one sampled finer than the solver records,
a fine short one solved only until it ends,
each the very bits of ``Rig.fire`` with the items the shot was fired with; a record past
the served scope's cost limit refused at the setting command, the settings unchanged; a
``CURVe?`` without a record answered at once, its reason in the queue."""
import time

import numpy as np
import pytest

from instruments.virtual_scope.instrument import VirtualScope
from rig.experiment.shot import Rig
from rig.lab.shots import SceneShots

SCENE = "ptfe52_magnetic"  # solver.duration 3 ms, solver.sample_interval 0.1 us


def ask(session, text: str) -> str:
    return session.handle(text.encode()).decode().strip()


@pytest.fixture(scope="module")
def served():
    """(scope, shots) of an mso4 on the scene, its first shot fired."""
    shots = SceneShots(SCENE)
    scope = VirtualScope(shots.rig().scope, shots, personality_name="mso4", seed=3, validate=shots.validate,
                         record_cost=shots.record_cost)
    scope.acq.first_acquisition()
    yield scope, shots
    scope.close()


def fire(session) -> str:
    return ask(session, "ACQ:STOPA SEQ;STATE ON;*OPC?;:ALLEV?")


def same_as_rig_fire(shots) -> None:
    shot = shots.last
    again = Rig.from_scene(SCENE, shot.overrides).fire(seed=shot.seed)
    for ch, w in shot.scope.waveforms.items():
        assert np.array_equal(w.codes, again.scope[ch].codes)
        assert w.preamble == again.scope[ch].preamble


def test_a_record_longer_than_the_scenes_solve_is_solved_for_and_is_rig_fire_with_its_items(served):
    scope, shots = served
    s = scope.open_session("t")
    assert ask(s, "HOR:RECO 10000;:HOR:SCA 1E-3;:ALLEV?") == '0,"No events to report - queue empty"'
    assert fire(s) == '1;0,"No events to report - queue empty"'
    record = shots.last.scope
    assert record.triggered and record["CH1"].preamble.x_increment == pytest.approx(1e-6, rel=1e-12)
    # 10 ms recorded, 90% after the trigger: the chain solved past the scene's 3 ms
    duration = Rig.from_scene(SCENE, shots.last.overrides).solver.duration
    assert duration > 9e-3 and any(o.startswith("solver.duration=") for o in shots.last.overrides)
    truth = shots.last.truth
    assert (len(truth.gauges["lower"].average_force) - 1) * truth.sample_interval == pytest.approx(duration, rel=1e-6)
    # past the pulses the chain rings and settles: the record's last tenth is well below the peak
    v = record["CH2"].volts()
    assert np.abs(v[-1000:] - np.median(v[-1000:])).max() < 0.5 * (v.max() - np.median(v[-1000:]))
    same_as_rig_fire(shots)


def test_a_record_finer_than_the_solvers_grid_samples_the_solution_finer(served):
    scope, shots = served
    s = scope.open_session("t")
    assert ask(s, "HOR:RECO 100000;:HOR:SCA 2E-5;:ALLEV?") == '0,"No events to report - queue empty"'
    assert fire(s) == '1;0,"No events to report - queue empty"'
    w = shots.last.scope["CH1"]
    assert w.preamble.x_increment == pytest.approx(2e-9, rel=1e-12) and w.preamble.points == 100_000
    assert "solver.sample_interval=2e-09 s" in shots.last.overrides  # the solver recorded at the scope's rate
    # no held values: the solution the scope sampled has a new value every 2 ns on the pulse's
    # rise (a hold of the 0.1 us grid would repeat each value 50 times)
    force = shots.last.truth.gauges["upper"].average_force
    assert shots.last.truth.sample_interval == pytest.approx(2e-9, rel=1e-12)
    rise = np.flatnonzero(force > 0.5 * force.max())[0]
    assert np.count_nonzero(np.diff(force[rise - 500:rise]) > 0) == 499
    same_as_rig_fire(shots)


def test_a_fine_short_record_solves_the_chain_only_until_it_ends_as_the_scenes_solve_does(served):
    """200 ns/div, 10,000 points (0.2 ns a sample) over the scene's whole 3 ms would hold
    2.4 GB: solved only until the record ends (its trigger, estimated, and the 1.8 us after
    it), it gives a record, the chain's forces those of the scene's own solve within the
    solver's accuracy (1e-4 of the peak), and the bits of Rig.fire with its items."""
    scope, shots = served
    s = scope.open_session("t")
    assert ask(s, "HOR:RECO 10000;:HOR:SCA 2E-7;:ALLEV?") == '0,"No events to report - queue empty"'
    assert fire(s) == '1;0,"No events to report - queue empty"'
    fine = shots.last
    w = fine.scope["CH1"]
    assert fine.scope.triggered and w.preamble.x_increment == pytest.approx(2e-10, rel=1e-12)
    duration = Rig.from_scene(SCENE, fine.overrides).solver.duration
    assert fine.scope.trigger_time + 0.9 * 2e-6 < duration < 0.25 * 3e-3  # past the record's end, a sixth of 3 ms
    coarse = shots.rig({}).truth()
    step = round(coarse.sample_interval / fine.truth.sample_interval)
    for name, g in coarse.gauges.items():
        f = fine.truth.gauges[name].average_force[::step]
        peak = g.average_force.max()
        assert np.abs(f - g.average_force[:f.size]).max() < 1e-4 * peak
    same_as_rig_fire(shots)
    ask(s, "HOR:RECO 10000;:HOR:SCA 1E-4")


def test_a_record_past_the_cost_limit_is_refused_at_the_setting_and_nothing_changes(served):
    """10,000,000 points at 200 us/div (5 GS/s, within the MSO44's 6.25 GS/s): 0.2 ns a
    sample over the 2.3 ms to the record's end, past the 2 GB limit."""
    scope, _ = served
    s = scope.open_session("t")
    s.handle(b"HOR:RECO 10000;:HOR:SCA 2E-4")
    before = ask(s, "HOR:RECO?;:HOR:SCA?")
    assert before == "10000;200.0000E-6"
    reply = ask(s, "HOR:RECO 10000000;:ALLEV?")
    assert reply.startswith('221,"Settings conflict; this record needs about') and "2 GB" in reply
    assert ask(s, "HOR:RECO?;:HOR:SCA?") == before


def test_curve_without_a_record_answers_at_once_with_an_empty_block_and_the_reason_queued():
    shots = SceneShots(SCENE)
    scope = VirtualScope(shots.rig().scope, shots, personality_name="tds2000")
    try:
        s = scope.open_session("t")
        assert s.handle(b"CURVE?") == b"#10\n"
        assert ask(s, "DATA:ENC ASCII;:CURVE?") == ""
        events = ask(s, "ALLEV?")
        assert events.count("has no record: no record yet") == 2
    finally:
        scope.close()


def test_auto_gives_an_untriggered_record_that_is_rig_fire_with_its_items_and_normal_none(served):
    """A rising edge at -0.4 V on gauges resting at 0 V never fires. TRIGger:A:MODe AUTO: the
    shot gives a record all the same, untriggered, with no event, the very bits of Rig.fire
    with the items it was fired with (scope.trigger.mode=auto among them); the gauges' pulses
    are in it, its trigger point at the impact. NORMal (the manuals: "waits for a valid
    trigger event"): the level the rig refuses for `rig shot` (a rising trigger below the
    gauges' rest) is a trigger that never comes: the armed scope waits, nothing solved, no
    event, until TRIGger FORCe gives the record AUTO gives, Rig.fire's with its items."""
    scope, shots = served
    s = scope.open_session("t")
    s.handle(b"*RST;:TRIG:A:MODE AUTO;:TRIG:A:EDGE:SLOPE RISE;:TRIG:A:LEVEL -0.4")
    assert fire(s) == '1;0,"No events to report - queue empty"'
    record = shots.last.scope
    assert not record.triggered and record.trigger_time == 0.0 and record.reason.startswith("auto-triggered")
    assert "scope.trigger.mode=auto" in shots.last.overrides and "scope.trigger.level=-0.4 V" in shots.last.overrides
    w = record["CH1"]
    assert w.preamble.points == scope.settings["scope.record_length"] and w.preamble.extra["auto_triggered"]
    assert -w.preamble.trigger_index * w.preamble.x_increment <= w.preamble.x_zero < 0  # the impact in the record
    assert np.ptp(w.codes.astype(int)) > 25  # the pulse, not the rest alone
    same_as_rig_fire(shots)
    s.handle(b"TRIG:A:MODE NORMAL")
    kept, seed = shots.last, int(ask(s, "RIG:SEED?"))
    s.handle(b"ACQ:STOPA SEQ;STATE ON")
    for _ in range(1000):
        if ask(s, "RIG:SEED?") == str(seed + 1) and not scope.acq.busy:
            break
        time.sleep(0.01)
    assert ask(s, "BUSY?;:ACQ:STATE?;:TRIG:STATE?;:ALLEV?") == '1;1;READY;0,"No events to report - queue empty"'
    assert shots.last is kept  # nothing solved or fired for a trigger that never fires
    assert ask(s, "TRIGGER FORCE;*OPC?;:BUSY?;:ALLEV?") == '1;0;0,"No events to report - queue empty"'
    forced = shots.last
    assert forced.seed == seed + 1 and not forced.scope.triggered and "scope.trigger.mode=auto" in forced.overrides
    same_as_rig_fire(shots)
    s.handle(b"*RST")
