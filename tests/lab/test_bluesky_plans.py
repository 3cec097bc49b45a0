"""The rig's devices in bluesky's standard plans, and plans paused and resumed, under a real
RunEngine (rig/lab/bluesky.py, plans.py): documents valid against event-model's schemas, one
event per planned shot with the settings it was fired with, seq_num 1..n once each, the seeds
N, N+1, ... once each. A pause (one Ctrl-C, or a deferred request) stops at the checkpoint
before a shot, with no shot in flight; an immediate one (Ctrl-C twice, ``request_pause()``)
catches a shot in flight, which resume fires again at its own seed."""
import asyncio
import os
import signal
import threading
import time

import numpy as np
import pytest

pytest.importorskip("ophyd_async")
pytest.importorskip("bluesky")
event_model = pytest.importorskip("event_model")

import bluesky.plans as bp
from bluesky import RunEngine
from bluesky.utils import RunEngineInterrupted
from ophyd_async.plan_stubs import ensure_connected

from instruments.errors import InstrumentError
from rig.experiment.scene import load
from rig.experiment.shot import Rig
from rig.lab.backend import InProcessBench
from rig.lab.bluesky import Magnet, Striker, VirtualScope
from rig.lab.plans import magnet_force_scan

SCENE = "ptfe52_magnetic"
QUICK = ("solver.duration=1.5 ms", "scope.record_length=2500", "scope.sample_interval=0.4 us")  # ~1 ms record
FIRST_SEED = 11


class Recorder:
    """The (name, document) pairs a RunEngine emits, across pauses and resumes, while in its
    ``with`` block."""

    def __init__(self, run_engine):
        self.run_engine, self.docs = run_engine, []

    def __enter__(self):
        self.token = self.run_engine.subscribe(lambda name, doc: self.docs.append((name, doc)))
        return self

    def __exit__(self, *exc):
        self.run_engine.unsubscribe(self.token)

    def events(self) -> list:
        return [doc for name, doc in self.docs if name == "event"]


def checked_events(docs, planned: int) -> list:
    """The events of one run after checking its documents: each valid against its schema,
    start, descriptor, ``planned`` events, stop, in that order and linked, seq_num 1..planned."""
    for name, doc in docs:
        event_model.schema_validators[event_model.DocumentNames[name]].validate(doc)
    names = [name for name, _ in docs]
    assert names == ["start", "descriptor"] + ["event"] * planned + ["stop"], names
    start, descriptor, stop = docs[0][1], docs[1][1], docs[-1][1]
    events = [doc for _, doc in docs[2:-1]]
    assert descriptor["run_start"] == start["uid"] and stop["run_start"] == start["uid"]
    assert all(e["descriptor"] == descriptor["uid"] for e in events)
    assert [e["seq_num"] for e in events] == list(range(1, planned + 1))
    assert stop["exit_status"] == "success" and stop["num_events"] == {"primary": planned}
    return events


def seeds(events) -> list:
    return [e["data"]["scope-seed"] for e in events]


def assert_is_the_shot(event) -> None:
    """The event's waveforms are those of ``Rig.fire`` at its seed and the settings it read
    back (as the devices set them; a setting not read is the scene's)."""
    data = event["data"]
    items = tuple(f"{key}={data[name]!r} {unit}" for key, name, unit in
                  [("magnet.force", "magnet-force", "N"), ("striker.velocity", "striker-velocity", "m/s")]
                  if name in data)
    shot = Rig(load(SCENE, QUICK + items)).fire(seed=data["scope-seed"])
    for ch, w in shot.scope.waveforms.items():
        assert np.array_equal(np.asarray(data[f"scope-{ch.lower()}-waveform"]), w.volts()), (data["scope-seed"], ch)


def devices(bench):
    scope, magnet, striker = (VirtualScope(bench, name="scope"), Magnet(bench, name="magnet"),
                              Striker(bench, name="striker"))
    run_engine = RunEngine({})
    run_engine(ensure_connected(scope, magnet, striker))
    return run_engine, scope, magnet, striker


def test_a_shot_fired_again_at_its_seed_is_the_same_shot_and_the_sequence_goes_on():
    bench = InProcessBench(SCENE, QUICK, seed=FIRST_SEED)
    first = bench.fire()
    again = bench.fire(seed=FIRST_SEED)
    assert (again.seed, bench.fired, bench.next_seed) == (FIRST_SEED, 2, FIRST_SEED + 1)
    assert all(np.array_equal(first.record[ch].codes, again.record[ch].codes) for ch in bench.channels)
    assert bench.fire().seed == FIRST_SEED + 1
    for seed in (FIRST_SEED + 2, FIRST_SEED - 1, True):  # not given yet, before N, not a seed
        with pytest.raises(InstrumentError, match="not one this rig has fired a shot at") as err:
            bench.fire(seed=seed)
        assert "\n" not in str(err.value)
    assert (bench.fired, bench.next_seed) == (3, FIRST_SEED + 2)


def test_the_scope_fires_a_shot_a_pause_caught_again_at_its_seed_and_a_read_shot_never():
    """A pause while a shot is in flight (triggered, not read): the next trigger waits for it
    and fires it again at its seed; a shot read is delivered: the next trigger fires the next."""
    bench = InProcessBench(SCENE, QUICK, seed=FIRST_SEED)
    scope = VirtualScope(bench, name="scope")

    async def run():
        await scope.connect()
        caught = scope.trigger()  # still firing as the pause comes
        scope.pause()
        scope.resume()
        await scope.trigger()
        await caught
        redone = scope.last.seed
        reading = await scope.read()
        scope.pause()
        scope.resume()
        await scope.trigger()
        return redone, reading["scope-seed"]["value"], scope.last.seed

    assert asyncio.run(run()) == (FIRST_SEED, FIRST_SEED, FIRST_SEED + 1)
    assert (bench.fired, bench.next_seed) == (3, FIRST_SEED + 2)


class PausingBench(InProcessBench):
    """The in-process rig where, once armed, ``pause()`` is called as the ``at``-th shot from
    then on is being fired, before it is solved: a pause that catches that shot in flight."""

    countdown = 0

    def arm(self, pause, at: int) -> None:
        self.pause, self.countdown = pause, at

    def fire(self, seed=None):
        self.countdown -= 1
        if self.countdown == 0:
            self.pause()
        return super().fire() if seed is None else super().fire(seed)


@pytest.fixture(scope="module")
def rig():
    """One rig and RunEngine for the standard plans, run one after another (the seeds go on);
    a run a failed test left paused is aborted."""
    bench = PausingBench(SCENE, QUICK, seed=FIRST_SEED)
    devs = devices(bench)
    yield (bench, *devs)
    if devs[0].state == "paused":
        devs[0].abort()


# plan(scope, magnet, striker) and the (force, velocity) of each event; None: as the rig is set
STANDARD = {
    "count": (lambda scope, magnet, striker: bp.count([scope, magnet, striker], num=3), [(None, None)] * 3),
    "scan": (lambda scope, magnet, striker: bp.scan([scope, striker], magnet, 2.0, 3.0, 2),
             [(2.0, None), (3.0, None)]),
    "list_scan": (lambda scope, magnet, striker: bp.list_scan([scope, magnet], striker, [0.7, 0.95]),
                  [(None, 0.7), (None, 0.95)]),
    "grid_scan": (lambda scope, magnet, striker: bp.grid_scan([scope], magnet, 2.0, 3.0, 2, striker, 0.7, 0.95, 2),
                  [(2.0, 0.7), (2.0, 0.95), (3.0, 0.7), (3.0, 0.95)]),
}


@pytest.mark.parametrize("paused", [False, True], ids=["run", "paused"])
@pytest.mark.parametrize("name", list(STANDARD))
def test_blueskys_standard_plans_give_valid_runs_one_seed_per_event_with_its_settings(rig, name, paused):
    """Each plan run through, and run with a pause at once as its second shot is fired (that
    shot fired again, at its seed, on resume)."""
    bench, run_engine, scope, magnet, striker = rig
    plan, settings = STANDARD[name]
    before = (bench.value("magnet.force"), bench.value("striker.velocity"))
    first, fired = bench.next_seed, bench.fired
    with Recorder(run_engine) as recorder:
        if paused:
            bench.arm(run_engine.request_pause, at=2)
            with pytest.raises(RunEngineInterrupted):
                run_engine(plan(scope, magnet, striker))
            assert run_engine.state == "paused" and len(recorder.events()) == 1
            run_engine.resume()
        else:
            run_engine(plan(scope, magnet, striker))
    events = checked_events(recorder.docs, len(settings))
    assert seeds(events) == list(range(first, first + len(settings)))  # none skipped, none twice
    assert bench.fired == fired + len(settings) + paused and bench.next_seed == first + len(settings)
    for e, (force, velocity) in zip(events, settings):
        before = (before[0] if force is None else force, before[1] if velocity is None else velocity)
        assert (e["data"]["magnet-force"], e["data"]["striker-velocity"]) == before
    assert_is_the_shot(events[-1])


def test_the_force_scan_has_a_checkpoint_before_each_shot():
    """A checkpoint before each shot and before the move to a force (as one_nd_step)."""
    bench = InProcessBench(SCENE, QUICK, seed=1)
    scope, magnet = VirtualScope(bench, name="scope"), Magnet(bench, name="magnet")
    commands = [msg.command for msg in magnet_force_scan(scope, magnet, [2.0, 3.0], shots=2)]
    shots = [k for k, c in enumerate(commands) if c == "trigger"]
    assert len(shots) == 4 and commands.count("checkpoint") == 4
    for k in shots:  # back from each trigger: a set (the move) or nothing, then the checkpoint
        back = [c for c in commands[:k] if c in ("checkpoint", "set", "save")]
        assert back[-1] == "checkpoint" or back[-2:] == ["checkpoint", "set"], commands


def ctrl_c() -> None:
    """Ctrl-C in the terminal: SIGINT to this process (the RunEngine, run from the main
    thread, has its handler installed while it runs)."""
    os.kill(os.getpid(), signal.SIGINT)


def ctrl_c_twice(run_engine) -> None:
    """Ctrl-C twice, as a person does it (bluesky counts presses at least 0.1 s apart); returns
    once the RunEngine is pausing (or after 10 s)."""
    pausing = threading.Event()
    run_engine.state_hook = lambda new, old: pausing.set() if new == "pausing" else None
    ctrl_c()
    time.sleep(0.25)
    ctrl_c()
    pausing.wait(10)
    run_engine.state_hook = None


@pytest.mark.parametrize("pause_at, how", [
    (3, "request_pause"),  # the first shot at 3.1 N: the move to it is redone too
    (2, "ctrl_c_twice"),
])
def test_a_pause_that_catches_a_shot_in_flight_has_resume_fire_it_again_at_its_own_seed(pause_at, how):
    """The force scan (2 forces x 2 shots) paused at once as a shot is fired."""
    planned = 4
    bench = PausingBench(SCENE, QUICK, seed=FIRST_SEED)
    run_engine, scope, magnet, striker = devices(bench)
    bench.arm(run_engine.request_pause if how == "request_pause" else lambda: ctrl_c_twice(run_engine), at=pause_at)
    with Recorder(run_engine) as recorder:
        with pytest.raises(RunEngineInterrupted):
            run_engine(magnet_force_scan(scope, magnet, [2.0, 3.1], shots=2))
        assert run_engine.state == "paused"
        assert len(recorder.events()) == pause_at - 1  # the caught shot's event is not emitted
        run_engine.resume()
    assert run_engine.state == "idle"
    events = checked_events(recorder.docs, planned)
    assert seeds(events) == list(range(FIRST_SEED, FIRST_SEED + planned))  # none skipped, none twice
    # one shot more than events: the caught one, fired again at its own seed
    assert bench.fired == planned + 1 and bench.next_seed == FIRST_SEED + planned
    assert_is_the_shot(events[pause_at - 1])


def ctrl_c_once(run_engine) -> None:
    """Ctrl-C once; returns once the RunEngine has taken the deferred pause (or after 10 s)."""
    ctrl_c()
    deadline = time.monotonic() + 10
    while not run_engine.deferred_pause_requested and time.monotonic() < deadline:
        time.sleep(0.005)


@pytest.mark.parametrize("how", ["ctrl_c", "request_pause(defer=True)"])
def test_ctrl_c_pauses_at_the_next_checkpoint_and_resume_goes_on_from_there(how):
    """One Ctrl-C, or a deferred pause, as the second of 6 shots is fired: the RunEngine
    pauses at the checkpoint before the third, with no shot in flight; resume fires the
    rest, each once."""
    planned = 6
    bench = PausingBench(SCENE, QUICK, seed=FIRST_SEED)
    run_engine, scope, magnet, striker = devices(bench)
    bench.arm((lambda: ctrl_c_once(run_engine)) if how == "ctrl_c" else
              (lambda: run_engine.request_pause(defer=True)), at=2)
    with Recorder(run_engine) as recorder:
        with pytest.raises(RunEngineInterrupted):
            run_engine(magnet_force_scan(scope, magnet, [2.0, 3.1], shots=3))
        assert run_engine.state == "paused"
        assert len(recorder.events()) == 2 and bench.fired == 2  # the shot in flight finished: none to redo
        run_engine.resume()
    assert run_engine.state == "idle"
    events = checked_events(recorder.docs, planned)
    assert seeds(events) == list(range(FIRST_SEED, FIRST_SEED + planned))
    assert bench.fired == planned
    assert [e["data"]["magnet-force"] for e in events] == [2.0] * 3 + [3.1] * 3
