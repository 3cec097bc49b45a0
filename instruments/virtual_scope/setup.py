"""Save and recall set-up (programmer manuals, "Save and Recall Command Group"): ``SET?``
and its IEEE 488.2 twin ``*LRN?``.

The answer is the scope's settings as the commands that set them, headers always on, long
forms (``:CH1:SCALE 5.0E-2;:CH1:POSITION -1.0E0;...``), whatever HEADer and VERBose say (the
manuals: "SET? always returns command headers"), so that a program can send it back to
restore the set-up. Every setting the emulation keeps is in it: per channel scale,
position, offset, coupling, bandwidth and probe; horizontal scale, position and (where the
model has it) record length; the edge trigger; the acquisition; the channels shown; the
DATa selection. The rig's own RIG: settings are not (``RIG:OVERRIDES?`` gives them)."""
from __future__ import annotations

from ..scpi.engine import Engine, ReplyForm
from ..scpi.status import StatusModel
from .commands import CHANNEL_WORDS

CHANNEL_SETTINGS = ("SCAle", "POSition", "OFFSet", "COUPling", "BANdwidth", "PRObe")
SETTINGS = ("HORizontal:SCAle", "HORizontal:POSition", "TRIGger:A:EDGE:SOUrce", "TRIGger:A:EDGE:SLOpe",
            "TRIGger:A:LEVel", "ACQuire:MODe", "ACQuire:NUMAVg", "ACQuire:STOPAfter", "DATa:SOUrce", "DATa:ENCdg",
            "DATa:WIDth", "DATa:STARt", "DATa:STOP")


def setup_queries(record_length: bool) -> str:
    """The program message whose answers are the set-up (``record_length``: the model sets
    HORizontal:RECOrdlength)."""
    per_channel = [f"{ch}:{name}" for ch in CHANNEL_WORDS for name in CHANNEL_SETTINGS]
    shown = [f"SELect:{ch}" for ch in CHANNEL_WORDS]
    horizontal = ["HORizontal:RECOrdlength"] if record_length else []
    return ";:".join(f"{q}?" for q in horizontal + per_channel + shown + list(SETTINGS))


def register(tree, scope) -> None:
    """Add ``SET?`` and ``*LRN?`` of ``scope`` (a VirtualScope) to a command tree."""
    form = ReplyForm(header=True, verbose=True)
    engine = Engine(tree, StatusModel(), form)  # its own reply form and queue: the client's are untouched
    queries = setup_queries(len(scope.personality.record_lengths) > 1).encode()

    def setup(c) -> bytes:
        return engine.execute(queries, c.context).rstrip(b"\n")

    tree.add("SET", read=setup, bare=True)
    tree.add("*LRN", read=setup, bare=True)
