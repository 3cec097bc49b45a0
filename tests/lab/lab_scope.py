"""Helpers of the lab tests: the emulated scope driven by a real acquisition, no rig (a
shot source that applies the overrides to the scene's Oscilloscope and acquires a synthetic
pulse with the shot's seed), and a query's reply as text."""
import numpy as np

from instruments.devices.oscilloscope import CHANNELS, ChannelSettings, Oscilloscope, Timebase, Trigger
from instruments.errors import InstrumentError
from instruments.virtual_scope.settings import scene_settings, scope_of

H = 1e-7  # s, the synthetic input's sampling
VELOCITY = 0.9  # m/s, the striker velocity the pulse's amplitude scales with


def pulse(amp=0.2, n=80_000, at=2e-3, width=5e-5):
    """A Gaussian pulse (V) every H s, its peak at ``at`` s."""
    t = np.arange(n) * H
    return amp * np.exp(-(((t - at) / width) ** 2))


def scene_scope(length=2500, interval=2e-7):
    return Oscilloscope(channels={"CH1": ChannelSettings(0.05, -1.0, bandwidth=None),
                                  "CH2": ChannelSettings(0.1, bandwidth=20e6)},
                        timebase=Timebase(interval, length), trigger=Trigger("CH1", 0.05, "rising", 0.2))


def parsed(text: str, like):
    """An override's text as the type the scene holds (what the rig's scene loader does)."""
    if text == "full":
        return None
    if isinstance(like, str):
        return text
    if isinstance(like, int) and not isinstance(like, bool):
        return int(text)
    return float(text.split()[0])


class PulseSource:
    """ShotSource: the scene's scope with the overrides, acquiring pulse() on CH1 and a
    larger one on CH2 (both scaled by striker.velocity / 0.9 m/s; magnet keys taken, no
    effect); ``gate``, where set, holds
    each shot until it is set; ``calls`` lists (overrides, seed)."""

    def __init__(self, scene):
        self.scene, self.calls, self.gate = scene, [], None

    def __call__(self, overrides, seed):
        self.calls.append((dict(overrides), seed))
        if self.gate is not None:
            self.gate.wait(30)
        return self.record(overrides, seed)

    def record(self, overrides, seed):
        settings, channels, scale = scene_settings(self.scene), set(self.scene.channels), 1.0
        for key, text in overrides.items():
            if key == "striker.velocity":
                scale = float(text.split()[0]) / VELOCITY
                continue
            if key.startswith("magnet."):  # the synthetic pulse does not depend on the magnet
                continue
            if key not in settings:
                raise InstrumentError(f"{key} = {text!r}: not a scope key")
            settings[key] = parsed(text, settings[key])
            if key.startswith("scope.channels."):
                channels.add(key.split(".")[2])
        scope = scope_of(settings, [c for c in CHANNELS if c in channels], self.scene)
        return scope.acquire({"CH1": scale * pulse(), "CH2": scale * pulse(0.3)}, H, np.random.default_rng(seed))


def velocity_only(key, text):
    """A validate callable: m/s for the striker, N for the force, m for the position."""
    unit = {"striker.velocity": "m/s", "magnet.force": "N", "magnet.position": "m"}[key]
    parts = text.split()
    if len(parts) != 2 or parts[1] != unit:
        return f"{key} = {text!r}: a number and {unit}, e.g. 0.9 {unit}"
    return None


def ask(session, text: str) -> str:
    """A query's reply as text, without the newline."""
    reply = session.handle(text.encode())
    assert reply.endswith(b"\n"), (text, reply[:80])
    return reply[:-1].decode("latin-1")


def fire(session, timeout=30.0):
    """A single sequence, waited for with *OPC?."""
    session.handle(b"ACQuire:STOPAfter SEQuence;STATE ON")
    assert ask(session, "*OPC?") == "1"
