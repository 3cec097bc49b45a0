"""Holder and ring magnet."""
import numpy as np
import pytest

from rig import Bead, ForceSchedule, RigError, Striker
from rig.experiment.shot import Rig
from rig.model.apparatus import Holder, RingMagnet


def test_a_hanging_ring_pulls_with_its_weight_the_published_2p38_N():
    assert RingMagnet.hanging().force == pytest.approx(2.38, abs=0.01)
    assert RingMagnet.hanging(added_mass=0.191).force == pytest.approx(4.25, abs=0.01)


def test_sliding_the_ring_changes_the_force():
    m = RingMagnet(position=0.0, peak_force=6.0)
    z = np.linspace(0, 0.05, 501)
    F = np.array([m.force_at(x) for x in z])
    assert F.max() == pytest.approx(6.0, rel=1e-3)  # the settable peak pull
    assert abs(F[0]) < 0.1 * F.max()  # ring centred on the bead: almost no axial pull
    assert F[-1] < 0.05 * F.max()  # far away: none


def test_magnet_position_and_schedule_in_a_scene(tmp_path):
    from rig.experiment.scene import PUBLISHED_SCENES
    text = (PUBLISHED_SCENES / "daraio2006" / "ptfe52_magnetic.toml").read_text()
    f = tmp_path / "slid.toml"
    f.write_text(text.replace('force = "2.38 N"', 'position = "7 mm"'))
    rig = Rig.from_scene(f)
    assert rig.chain.top_force == pytest.approx(RingMagnet(position=7e-3).force_at(7e-3))
    f.write_text(text.replace('force = "2.38 N"', 'schedule = [["0 ms", "2.38 N"], ["1 ms", "4.25 N"]]'))
    rig = Rig.from_scene(f)
    assert isinstance(rig.chain.top_force, ForceSchedule)
    assert rig.chain.top_force.at(0.5e-3) == pytest.approx(3.315)
    with pytest.raises(RigError, match="exactly one of"):
        RingMagnet(force=2.38, position=0.01)


def test_holder_refuses_what_does_not_fit():
    h = Holder(bore=5e-3, length=0.1)
    with pytest.raises(RigError, match=r"beads\[0\]\.diameter.*wider than holder\.bore"):
        h.check([Bead("ptfe", "5.5 mm")])
    with pytest.raises(RigError, match="striker.diameter"):
        h.check([Bead("ptfe", "4.76 mm")], Striker(diameter="6 mm"))
    with pytest.raises(RigError, match="holder.length"):
        h.check([Bead("ptfe", "4.76 mm")] * 30)
    assert Holder(vertical=False).gravity == 0.0
