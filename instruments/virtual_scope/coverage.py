"""How much of each model's programmer manual the emulated scope answers.

The manuals' commands (instruments/virtual_scope/manuals/: the MDO3000's and the 4 Series'
written by tools/manual_commands.py from the command trees of tm_devices, which Tektronix
generates from the programmer manuals; the TDS2000's, which has no such tree, transcribed by
hand from its manual, 071-1075) are sent to an emulated scope one by one, <x> taken as 1: a
header the scope answers (or takes) is *implemented*; an enumerated value of it the scope
refuses with 221 "Settings conflict" is *refused by design* (a setting not emulated, such
as GND coupling); a header the scope does not know (113 "Undefined header") is *not
emulated*. ``python -m instruments.virtual_scope.coverage`` prints the table of
docs/reference/scpi-coverage.md."""
from __future__ import annotations

import re
from dataclasses import dataclass

from ..errors import InstrumentError
from .manual import MODELS, ManualCommand, manual

SHOWN = 6  # words refused by design named in a row of the table


@dataclass(frozen=True)
class Probe:
    """What the scope made of one manual command: ``status`` (implemented, not emulated),
    the query's answer (None: no query form, or none given), the words refused by design."""

    command: ManualCommand
    status: str
    answer: str | None
    refused: tuple


def events(session) -> list:
    """The codes of the events queued since the last call (ALLEv? read whole)."""
    reply = session.handle(b"ALLEV?").decode()
    return [int(code) for code in re.findall(r'(?:^|[ ,])(-?\d+),"', reply) if int(code) != 0]


def placeholder(args: str) -> str:
    """An argument of the syntax's kind for a set form that has no query to echo."""
    if "<" not in args and "{" not in args:  # a literal word (TRIGger FORCe)
        return args
    if "QString" in args:
        return '"x"'
    if "Block" in args:
        return "#10"
    return "1"


def probe(session, command: ManualCommand) -> Probe:
    """Send one command's query (and each of its enumerated words) to a session."""
    session.handle(b"*RST;:HEADER OFF;:VERBOSE ON;*CLS")
    answer, known = None, True
    if command.query:
        reply = session.handle(f"{command.concrete}?".encode()).decode().strip()
        answer = reply or None
        known = 113 not in events(session)
    refused = []
    if command.write and known:
        for word in command.words or ("",):
            if word == "" and command.args:  # a number, a string or a block: the query's own answer back
                word = answer if answer is not None else placeholder(command.args)
            session.handle(f"{command.concrete} {word}".strip().encode())
            codes = events(session)
            known = known and 113 not in codes
            if 221 in codes:
                refused.append(word)
    return Probe(command, "implemented" if known else "not emulated", answer, tuple(refused))


def table(probes: dict) -> str:
    """The coverage table (markdown): per model and group, the manual's headers, how many
    are implemented, how many words they refuse by design (the first SHOWN named), and the
    implemented headers."""
    out = ["| model | group | manual headers | implemented | words refused by design |", "|---|---|---|---|---|"]
    for model, found in probes.items():
        groups: dict = {}
        for p in found:
            groups.setdefault(p.command.group, []).append(p)
        for group, ps in groups.items():
            done = [p for p in ps if p.status == "implemented"]
            refused = [f"`{p.command.header} {w}`" for p in done for w in p.refused]
            shown = ", ".join(refused[:SHOWN]) + (f" and {len(refused) - SHOWN} more" if len(refused) > SHOWN else "")
            out.append(f"| {model} | {group} | {len(ps)} | {len(done)} | {len(refused)}: {shown or '-'} |")
    for model, found in probes.items():
        out += ["", f"Implemented on the {model}:", ""]
        groups = {}
        for p in found:
            if p.status == "implemented":
                groups.setdefault(p.command.group, []).append(f"`{p.command.header}`")
        out += [f"- {group}: {', '.join(heads)}" for group, heads in groups.items()]
    return "\n".join(out) + "\n"


def no_shots(overrides, seed):
    raise InstrumentError("no shots while the manual's commands are probed")


def probing_scope(model: str):
    """An emulated ``model`` of two channels whose shots are refused (a command is probed,
    never a record); close it after use."""
    from ..devices.oscilloscope import ChannelSettings, Oscilloscope, Timebase, Trigger
    from .instrument import VirtualScope

    scene = Oscilloscope(channels={"CH1": ChannelSettings(0.05), "CH2": ChannelSettings(0.05)},
                         timebase=Timebase(4e-7, 10_000), trigger=Trigger("CH1", 0.03, "rising", 0.1))
    return VirtualScope(scene, no_shots, personality_name=model, opc_timeout_s=1.0)


def probe_model(model: str) -> tuple:
    """The Probes of every command of a model's manual (``probing_scope``)."""
    scope = probing_scope(model)
    try:
        session = scope.open_session("coverage")
        return tuple(probe(session, c) for c in manual(model))
    finally:
        scope.close()


if __name__ == "__main__":
    print(table({model: probe_model(model) for model in MODELS}), end="")
