"""The rig's ophyd-async devices under a bluesky RunEngine (rig/lab/bluesky.py, plans.py):
the documents of a magnet-force scan, their schemas, and each event's shot equal to
``Rig.fire`` with the same settings and seed."""
import asyncio
import time

import numpy as np
import pytest

pytest.importorskip("ophyd_async")
pytest.importorskip("bluesky")
event_model = pytest.importorskip("event_model")

from bluesky import RunEngine
from bluesky.utils import FailedStatus
from ophyd_async.plan_stubs import ensure_connected

from instruments.errors import InstrumentError
from rig.errors import RigError
from rig.experiment.scene import load
from rig.experiment.shot import Rig
from rig.lab.backend import InProcessBench
from rig.lab.bluesky import Magnet, Striker, VirtualScope
from rig.lab.plans import documents, magnet_force_scan, tiled_writer

SCENE = "ptfe52_magnetic"
QUICK = ("solver.duration=1.5 ms", "scope.record_length=2500", "scope.sample_interval=0.4 us")  # ~1 ms record
FIRST_SEED = 5


@pytest.fixture(scope="module")
def scan():
    """The documents of 2 forces x 2 shots, and the devices."""
    bench = InProcessBench(SCENE, QUICK, seed=FIRST_SEED)
    scope, magnet = VirtualScope(bench, name="scope"), Magnet(bench, name="magnet")
    run_engine = RunEngine({})
    run_engine(ensure_connected(scope, magnet))
    docs = documents(run_engine, magnet_force_scan(scope, magnet, [2.0, 3.1], shots=2))
    return docs, bench


def test_the_scan_emits_start_descriptor_events_stop_each_valid(scan):
    docs, _ = scan
    assert [name for name, _ in docs] == ["start", "descriptor"] + ["event"] * 4 + ["stop"]
    for name, doc in docs:
        event_model.schema_validators[event_model.DocumentNames[name]].validate(doc)
    start, descriptor, stop = docs[0][1], docs[1][1], docs[-1][1]
    assert start["forces_N"] == [2.0, 3.1] and start["shots_per_force"] == 2
    assert stop["exit_status"] == "success" and stop["num_events"] == {"primary": 4}
    assert descriptor["run_start"] == start["uid"] and all(d["descriptor"] == descriptor["uid"] for _, d in docs[2:6])
    keys = descriptor["data_keys"]
    assert keys["magnet-force"]["units"] == "N"  # the readback is read in every event, not configuration
    for ch in ("ch1", "ch2", "ch3"):
        assert keys[f"scope-{ch}-waveform"]["shape"] == [2500] and keys[f"scope-{ch}-waveform"]["units"] == "V"
        config = descriptor["configuration"]["scope"]["data"]
        assert config[f"scope-{ch}-sample_interval"] == pytest.approx(0.4e-6, rel=1e-12)
        assert config[f"scope-{ch}-points"] == 2500


def test_each_event_is_the_shot_rig_fire_gives_with_its_force_and_seed(scan):
    docs, bench = scan
    events = [doc for name, doc in docs if name == "event"]
    assert [e["data"]["magnet-force"] for e in events] == [2.0, 2.0, 3.1, 3.1]
    assert [e["data"]["scope-seed"] for e in events] == [FIRST_SEED + k for k in range(4)]
    assert bench.fired == 4
    for e in events:
        force, seed = e["data"]["magnet-force"], e["data"]["scope-seed"]
        shot = Rig(load(SCENE, QUICK + (f"magnet.force={force!r} N",))).fire(seed=seed)
        for ch, w in shot.scope.waveforms.items():
            got = np.asarray(e["data"][f"scope-{ch.lower()}-waveform"])
            assert got.dtype == np.float64 and np.array_equal(got, w.volts()), (seed, ch)
    first, third = (np.asarray(events[k]["data"]["scope-ch3-waveform"]) for k in (0, 2))
    assert not np.array_equal(first, third)  # another force, another shot


def test_a_trigger_fires_off_the_event_loop():
    """The loop keeps turning while the chain is solved (a force not solved before)."""
    bench = InProcessBench(SCENE, QUICK, seed=1)
    scope, striker = VirtualScope(bench, name="scope"), Striker(bench, name="striker")

    async def run():
        await scope.connect()
        await striker.connect()
        await striker.set(0.61)
        ticks = 0

        async def tick():
            nonlocal ticks
            while True:
                await asyncio.sleep(0.001)
                ticks += 1

        ticker = asyncio.create_task(tick())
        start = time.perf_counter()
        await scope.trigger()
        took = time.perf_counter() - start
        ticker.cancel()
        return ticks, took, await striker.velocity.get_value(), await scope.ch2.waveform.get_value()

    ticks, took, velocity, waveform = asyncio.run(run())
    assert velocity == 0.61 and waveform.size == 2500
    # blocking the loop gives 0 ticks; how many more it gets depends on the machine's load and
    # on the solver kernels holding the GIL, not on the device
    assert ticks >= 3, (ticks, took)


def test_a_refused_setting_fails_the_plan_with_the_rigs_one_line():
    bench = InProcessBench(SCENE, QUICK, seed=1)
    scope, magnet = VirtualScope(bench, name="scope"), Magnet(bench, name="magnet")
    run_engine = RunEngine({})
    run_engine(ensure_connected(scope, magnet))
    with pytest.raises(FailedStatus) as err:
        documents(run_engine, magnet_force_scan(scope, magnet, [float("nan")], shots=1))
    cause = err.value.__cause__ or err.value.args[0].exception()
    assert "magnet.force" in str(cause) and "\n" not in str(cause)
    assert bench.fired == 0 and bench.overrides == {}


def tiled_installed() -> bool:
    import importlib.util

    return importlib.util.find_spec("tiled") is not None


@pytest.mark.skipif(tiled_installed(), reason="tiled is installed: the example writes to a catalog")
def test_without_tiled_the_tiled_example_refuses_in_one_line():
    with pytest.raises(RigError, match="needs the tiled client") as err:
        tiled_writer("http://127.0.0.1:8000")
    assert "\n" not in str(err.value)


def test_a_shot_that_does_not_trigger_fails_the_trigger_with_the_scopes_reason():
    bench = InProcessBench(SCENE, QUICK, seed=1)
    scope = VirtualScope(bench, name="scope")
    bench.set("scope.trigger.level", "0.35 V")  # on screen (8 div x 50 mV), above every pulse of CH1

    async def run():
        await scope.connect()
        await scope.trigger()

    with pytest.raises(InstrumentError, match="did not trigger \\(seed 1\\)") as err:
        asyncio.run(run())
    assert "\n" not in str(err.value) and scope.last is None
