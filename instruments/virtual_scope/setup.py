"""Save and recall set-up (programmer manuals, "Save and Recall Command Group"): ``SET?``
and its IEEE 488.2 twin ``*LRN?``; on the TDS2000 the set-up locations, ``*SAV``/``*RCL`` and
``SAVe:SETUp``/``RECAll:SETUp`` (``RECAll:SETUp FACtory``: the settings ``*RST`` gives).

``SET?`` answers the scope's settings as the commands that set them, headers always on, long
forms (``:CH1:SCALE 5.0E-2;:CH1:POSITION -1.0E0;...``), whatever HEADer and VERBose say (the
manuals: "SET? always returns command headers"), so that a program can send it back to
restore the set-up. Every setting the emulation keeps is in it: per channel scale,
position, offset, coupling, bandwidth and probe; horizontal scale, position and (where the
model has them) record length, mode, MANual:CONFIGure and sample rate; the edge trigger;
the acquisition; the channels shown; the DATa selection. The rig's own RIG: settings are
not (``RIG:OVERRIDES?`` gives them).

On the TDS2000 (its manual's Save and Recall group) a set-up location, 1 to 10, keeps those
same settings from ``*SAV n`` or ``SAVe:SETUp n`` until the scope is closed (``*RST`` leaves
them, as the manual says); ``*RCL n`` or ``RECAll:SETUp n`` restores them at once, all or
none. A location never saved is -200, one outside 1 to 10 -222; a file path in place of a
location is -221: the emulated scope keeps no files. (The MDO3000's manual has the locations
too; they are not emulated on it, where SAVe:SETUp and RECAll:SETUp stay undefined headers.)"""
from __future__ import annotations

from dataclasses import dataclass

from ..scpi.engine import Call, Engine, ReplyForm
from ..scpi.status import ScpiError, StatusModel
from .commands import CHANNEL_WORDS

CHANNEL_SETTINGS = ("SCAle", "POSition", "OFFSet", "COUPling", "BANdwidth", "PRObe")
SETTINGS = ("HORizontal:SCAle", "HORizontal:POSition", "TRIGger:A:EDGE:SOUrce", "TRIGger:A:EDGE:SLOpe",
            "TRIGger:A:LEVel", "ACQuire:MODe", "ACQuire:NUMAVg", "ACQuire:STOPAfter", "DATa:SOUrce", "DATa:ENCdg",
            "DATa:WIDth", "DATa:STARt", "DATa:STOP")
LOCATIONS = {"tds2000": 10}
"""Set-up locations of the models they are emulated on (TDS1000/2000 manual: 1 to 10)."""


@dataclass(frozen=True)
class Saved:
    """What a set-up location keeps: the settings (scene keys), the channels shown, the DATa
    selection, the number of averages and the acquisition's stop condition."""

    settings: dict
    shown: frozenset
    data: object
    numavg: int
    stop_after: str


def setup_queries(record_length: bool, modes: bool = False) -> str:
    """The program message whose answers are the set-up (``record_length``: the model sets
    HORizontal:RECOrdlength; ``modes``: it has HORizontal:MODe, whose mode and sample rate come
    first, so that a set-up of either mode is restored in it: horizontal.py)."""
    per_channel = [f"{ch}:{name}" for ch in CHANNEL_WORDS for name in CHANNEL_SETTINGS]
    shown = [f"SELect:{ch}" for ch in CHANNEL_WORDS]
    horizontal = (["HORizontal:MODe", "HORizontal:MODe:MANual:CONFIGure", "HORizontal:MODe:SAMPLERate"]
                  if modes else []) + (["HORizontal:RECOrdlength"] if record_length else [])
    return ";:".join(f"{q}?" for q in horizontal + per_channel + shown + list(SETTINGS))


def register(tree, scope) -> None:
    """Add ``SET?``, ``*LRN?`` and the set-up locations of ``scope`` (a VirtualScope)."""
    form = ReplyForm(header=True, verbose=True)
    engine = Engine(tree, StatusModel(), form)  # its own reply form and queue: the client's are untouched
    queries = setup_queries(len(scope.personality.record_lengths) > 1, scope.personality.horizontal_modes).encode()

    def setup(c) -> bytes:
        return engine.execute(queries, c.context).rstrip(b"\n")

    tree.add("SET", read=setup, bare=True)
    tree.add("*LRN", read=setup, bare=True)
    if scope.personality.name in LOCATIONS:
        register_locations(tree, scope, LOCATIONS[scope.personality.name])


def register_locations(tree, scope, count: int) -> None:
    """*SAV, *RCL, SAVe:SETUp and RECAll:SETUp on ``count`` set-up locations."""
    kept: dict = {}  # location -> Saved; outlives *RST

    def location(c: Call) -> int:
        if c.arg().kind != "number":
            raise ScpiError(-221, f"{c.header} {c.arg().text[:40]}: set-up files are not emulated (no file "
                                  f"system); locations 1 to {count}")
        n = c.number()
        if n != round(n) or not 1 <= n <= count:
            raise ScpiError(-222, f"{c.header} {c.arg().text}: locations 1 to {count}")
        return round(n)

    def save(c: Call):
        kept[location(c)] = Saved(dict(scope.settings), frozenset(scope.shown), scope.data, scope.numavg,
                                  scope.acq.stop_after)

    def restore(c: Call):
        n = location(c)
        if n not in kept:
            raise ScpiError(-200, f"{c.header} {n}: no set-up saved in location {n} (*SAV {n})")
        s = kept[n]
        scope.change(dict(s.settings), shown=set(s.shown))
        scope.data, scope.numavg, scope.acq.stop_after = s.data, s.numavg, s.stop_after

    def recall(c: Call):
        """RECAll:SETUp FACtory (the settings *RST gives) or a location."""
        if c.arg().kind == "word":
            c.word(("FACtory",))
            scope.reset()
        else:
            restore(c)

    tree.add("SAVe:SETUp", write=save)
    tree.add("RECAll:SETUp", write=recall)
    tree.add("*SAV", write=save)
    tree.add("*RCL", write=restore)
