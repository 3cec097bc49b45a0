"""The overrides the emulated scope hands its shot source are scene overrides the rig reads
back as the same scope: every SCPI setting, on a published scene, through the rig's own
scene loader (``rig shot --set`` reads the same items). No shot is fired."""
import pytest

from instruments.virtual_scope.instrument import VirtualScope
from instruments.virtual_scope.settings import scope_of
from rig.experiment.scene import load
from rig.experiment.shot import Rig

SCENE = "ptfe52_magnetic"


def rig_scope(items=()):
    """The Oscilloscope of the scene with "key=value" items, as the rig builds it."""
    return Rig(load(SCENE, items)).scope


def never(overrides, seed):
    raise AssertionError("no shot is fired here")


@pytest.mark.parametrize("personality, commands", [
    ("tds2000", ""),
    ("mdo3000", ("CH1:SCA 0.1;POS 2;OFFS 0.01;COUP AC;BAN FULL;PRO 10;:SEL:CH4 ON;:CH4:SCA 0.2;:HOR:SCA 4E-4;"
                 "RECO 100000;:TRIG:A:LEV 0.04;EDGE:SLO FALL;SOU CH2;:ACQ:MOD AVE;NUMAV 16;:HOR:POS 30")),
    ("tds2000", "CH2:BAN OFF;:CH3:BAN ON;:HOR:MAIN:POS 1E-4;:ACQ:MODE SAMPLE;:SEL:CH2 OFF"),
    ("mso4", "HOR:RECO 20000;:CH1:BANDWIDTH 2.5E7;:RIG:STR:VEL 1.1 m/s;:RIG:MAG:FORC 2.0 N"),
])
def test_the_overrides_load_back_as_the_same_scope(personality, commands):
    base = rig_scope()
    scope = VirtualScope(base, never, personality_name=personality, scene_name=SCENE)
    try:
        session = scope.open_session("test")
        session.handle(commands.encode())
        assert session.handle(b"ALLEV?") == b'0,"No events to report - queue empty"\n'
        items = [f"{k}={v}" for k, v in scope.overrides().items()]
        rig = Rig(load(SCENE, items))
        with scope.cond:
            expected = scope_of(scope.settings, scope.channels(), base)
        assert rig.scope == expected
        assert rig.scene.values["striker"]["velocity"] == pytest.approx(1.1 if "STR:VEL" in commands else
                                                                        base_velocity())
    finally:
        scope.close()


def base_velocity():
    return load(SCENE).values["striker"]["velocity"]
