"""A property-based fuzz of the parser and the emulated scope: random bytes and random
valid-looking messages (every registered header, in long, short and mixed case forms, with
random arguments) never raise, never leave an internal fault, and *IDN? answers afterwards."""
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from instruments.scpi.engine import INTERNAL
from instruments.virtual_scope.instrument import VirtualScope
from lab.lab_scope import PulseSource, scene_scope, velocity_only


def patterns(node, prefix=()):
    """Every registered pattern of a command tree, as its mnemonics."""
    for child in node.children:
        path = prefix + (child.mnemonic,)
        if child.command is not None:
            yield path
        yield from patterns(child, path)


@pytest.fixture(scope="module")
def scope():
    scene = scene_scope(10_000)
    vs = VirtualScope(scene, PulseSource(scene), personality_name="mso4", validate=velocity_only,
                      opc_timeout_s=5.0, max_message_bytes=4096)
    yield vs
    vs.close()


def _headers() -> list:
    vs = VirtualScope(scene_scope(), PulseSource(scene_scope()), personality_name="mso4")
    try:
        return list(patterns(vs.engine.tree.root))
    finally:
        vs.close()


HEADERS = _headers()
ARGUMENTS = st.one_of(
    st.sampled_from(["ON", "OFF", "1", "0", "CH1", "CH3", "RIB", "ASCII", "SEQ", "RUNSTOP", "FORCE", "AVERAGE",
                     "50mV", "10 us", "1E-3", "-5", "2500", "1E308", "1e999", "0.9 m/s", "#H1F", "#15hello", "#0",
                     '"a;b"', "'x'", "", ",", "MAX", "NaN", "inf"]),
    st.floats(allow_nan=False, allow_infinity=False).map(repr),
    st.integers(-2 ** 70, 2 ** 70).map(str))


@st.composite
def unit(draw):
    mnemonics = draw(st.sampled_from(HEADERS))
    words = []
    for m in mnemonics:
        form = draw(st.sampled_from([m.long, m.short, m.long.lower(), m.short.title()]))
        suffix = draw(st.sampled_from(["", "1", "2", "4", "9"])) if m.numbered else ""
        words.append(form + suffix)
    head = draw(st.sampled_from(["", ":"])) + ":".join(words) + draw(st.sampled_from(["", "?"]))
    args = draw(st.lists(ARGUMENTS, max_size=3))
    return head + (" " + ",".join(args) if args else "")


def check_alive(scope):
    session = scope.open_session("check")
    assert session.handle(b"*IDN?") == b"TEKTRONIX,MSO44,C010001,CF:91.1CT FV:2.0.3.950\n"
    events = []
    while scope.status.events:
        events.append(scope.status.next_event())
    assert not [e for e in events if INTERNAL in e.detail]


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(message=st.binary(max_size=300))
def test_random_bytes(scope, message):
    scope.open_session("fuzz").handle(message)
    check_alive(scope)


@settings(max_examples=400, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(units=st.lists(unit(), min_size=1, max_size=5), sep=st.sampled_from([";", ";:", "; "]))
def test_valid_looking_messages(scope, units, sep):
    session = scope.open_session("fuzz")
    session.handle(sep.join(units).encode())
    session.handle(b"*RST")
    check_alive(scope)
