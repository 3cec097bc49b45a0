"""The emulated scope's settings as the rig's scene keys, and what differs from the scene.

Every front-panel setting the SCPI commands change is a scene key of the scope
(``scope.channels.CH1.volts_per_div``, ``scope.record_length``, ...; the rig's SCHEMA in its
scene module, the fields of ``instruments.devices.oscilloscope``), held as its SI value. The shot
source is handed the settings that differ from the scene as loaded, as text with the key's
unit (``"0.05 V"``, ``"1e-06 s"``, ``"2500"``), the form ``rig shot --set KEY=VALUE`` takes.
A channel the scene does not set up is acquired only once it is switched on, and then with
all of its settings (so a shot reproduced from the overrides draws the same noise); a scene
channel switched off is still acquired (the rig decides what it records) but not shown."""
from __future__ import annotations

from dataclasses import fields

from ..devices.oscilloscope import CHANNELS, ChannelSettings, Oscilloscope, Timebase, Trigger

UNITS = {"sample_interval": "s", "level": "V", "volts_per_div": "V", "offset": "V", "bandwidth": "Hz"}
CHANNEL_FIELDS = tuple(f.name for f in fields(ChannelSettings))


def channel_key(channel: str, field: str) -> str:
    return f"scope.channels.{channel}.{field}"


def scene_settings(scope: Oscilloscope) -> dict:
    """{scene key: SI value} of a scope, every channel's settings included (a channel the
    scene does not set up has ChannelSettings' defaults)."""
    tb, tr = scope.timebase, scope.trigger
    out = {"scope.sample_interval": float(tb.sample_interval), "scope.record_length": int(tb.record_length),
           "scope.mode": scope.mode, "scope.averages": int(scope.averages),
           "scope.trigger.source": tr.source, "scope.trigger.level": float(tr.level),
           "scope.trigger.slope": tr.slope, "scope.trigger.pre_trigger": float(tr.pre_trigger),
           "scope.trigger.mode": tr.mode}
    for ch in CHANNELS:
        s = scope.channels.get(ch, ChannelSettings())
        out.update({channel_key(ch, f): getattr(s, f) for f in CHANNEL_FIELDS})
    return out


def value_text(key: str, value) -> str:
    """A setting as the text of a scene override: SI number and unit (``0.05 V``), a
    whole number, a word, ``full`` for no bandwidth limit."""
    if value is None:
        return "full"
    if isinstance(value, str):
        return value
    if isinstance(value, int):
        return str(value)
    unit = UNITS.get(key.rsplit(".", 1)[-1])
    return f"{float(value)!r} {unit}" if unit else repr(float(value))


def acquired(scene: Oscilloscope, shown: set) -> tuple:
    """The channels a shot records: the scene's, and those switched on, in CH1..CH4 order."""
    return tuple(ch for ch in CHANNELS if ch in scene.channels or ch in shown)


def overrides(scene: Oscilloscope, now: dict, channels) -> dict:
    """{key: text} of every setting in ``now`` that differs from the scene's, with all
    settings of a recorded channel the scene lacks; channels not recorded left out."""
    loaded, out = scene_settings(scene), {}
    for key, value in now.items():
        if key.startswith("scope.channels."):
            ch = key.split(".")[2]
            if ch not in channels:
                continue
            if ch not in scene.channels:
                out[key] = value_text(key, value)
                continue
        if loaded[key] != value:
            out[key] = value_text(key, value)
    return out


def scope_of(settings: dict, channels, base: Oscilloscope) -> Oscilloscope:
    """The Oscilloscope the settings describe, recording ``channels`` (InstrumentError for
    settings it refuses, e.g. a trigger on a channel that is not recorded)."""
    chans = {ch: ChannelSettings(**{f: settings[channel_key(ch, f)] for f in CHANNEL_FIELDS}) for ch in channels}
    return Oscilloscope(channels=chans,
                        timebase=Timebase(settings["scope.sample_interval"], settings["scope.record_length"]),
                        trigger=Trigger(settings["scope.trigger.source"], settings["scope.trigger.level"],
                                        settings["scope.trigger.slope"], settings["scope.trigger.pre_trigger"],
                                        settings["scope.trigger.mode"]),
                        mode=settings["scope.mode"], averages=settings["scope.averages"],
                        noise_floor=base.noise_floor, model=base.model)
