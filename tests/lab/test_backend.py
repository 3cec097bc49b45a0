"""The in-process backend of the lab devices (rig/lab/backend.py): settings read back in SI,
refusals that change nothing, the k-th shot at seed N + k - 1 with the settings it was fired
with."""
import numpy as np
import pytest

from instruments.errors import InstrumentError
from rig.errors import RigError
from rig.experiment.scene import load
from rig.experiment.shot import Rig
from rig.lab.backend import InProcessBench

SCENE = "ptfe52_magnetic"
QUICK = ("solver.duration=1.5 ms", "scope.record_length=2500", "scope.sample_interval=0.4 us")


def test_a_setting_reads_back_in_si_and_a_refusal_changes_nothing():
    bench = InProcessBench(SCENE, QUICK, seed=3)
    assert bench.channels == ("CH1", "CH2", "CH3")
    assert bench.value("magnet.force") == pytest.approx(2.38, rel=1e-12)  # the scene as served
    bench.set("magnet.force", "2700 mN")
    bench.set("striker.velocity", "1.1")  # a plain number is in SI, as with --set
    assert bench.value("magnet.force") == pytest.approx(2.7, rel=1e-12)
    assert bench.value("striker.velocity") == pytest.approx(1.1, rel=1e-12)
    with pytest.raises(InstrumentError, match="striker.velocity") as err:
        bench.set("striker.velocity", "1.1 N")
    assert "\n" not in str(err.value)
    with pytest.raises(InstrumentError, match="give exactly one of force, position"):
        bench.set("magnet.position", "5 cm")  # the scene gives the force
    with pytest.raises(InstrumentError, match="magnet.position: not set"):
        bench.value("magnet.position")
    with pytest.raises(InstrumentError, match="a rising trigger needs a level above the gauges' rest"):
        bench.set("scope.trigger.level", "-0.1 V")  # NORMal: refused, as rig shot refuses it
    assert bench.overrides == {"magnet.force": "2700 mN", "striker.velocity": "1.1"}


def test_the_kth_shot_is_fired_at_seed_n_plus_k_minus_1_with_its_settings():
    bench = InProcessBench(SCENE, QUICK, seed=40)
    first = bench.fire()
    bench.set("magnet.force", "3 N")
    second = bench.fire()
    assert (first.seed, second.seed, bench.fired) == (40, 41, 2)
    assert first.overrides == () and second.overrides == ("magnet.force=3 N",)
    for fired in (first, second):
        shot = Rig(load(SCENE, QUICK + fired.overrides)).fire(seed=fired.seed)
        assert all(np.array_equal(shot.scope[ch].codes, fired.record[ch].codes) for ch in bench.channels)


@pytest.mark.parametrize("seed", [-1, 2**63, 1.5, True])
def test_a_bad_first_seed_is_refused(seed):
    with pytest.raises(RigError, match="seed"):
        InProcessBench(SCENE, QUICK, seed=seed)
