"""The lab tests' fixture: an emulated scope on a synthetic shot source (lab_scope.py)."""
import pytest
from lab_scope import PulseSource, scene_scope, velocity_only

from instruments.virtual_scope.instrument import VirtualScope


@pytest.fixture
def make_scope():
    """make_scope(personality="tds2000", **kw) -> (VirtualScope, session, PulseSource)."""
    made = []

    def make(personality="tds2000", scene=None, **kw):
        scene = scene or scene_scope(10_000 if personality != "tds2000" else 2500)
        source = PulseSource(scene)
        scope = VirtualScope(scene, source, personality_name=personality, validate=velocity_only,
                             scene_name="synthetic", **kw)
        made.append(scope)
        return scope, scope.open_session("test"), source

    yield make
    for scope in made:
        scope.close()
