"""Measurements on the last record (programmer manuals, "Measurement" command group):
the immediate one, ``MEASUrement:IMMed:TYPe/SOUrce/VALue?/UNIts?``, and the numbered slots
``MEASUrement:MEAS<n>:TYPe/SOUrce/STATE/VALue?/UNIts?`` (n = 1..8). Period-free types
only: AMPlitude and PK2pk (max - min: the min-max method of HIGH and LOW), MAXimum,
MINimum, HIGH, LOW, MEAN, RMS, in volts. Without a record the value is 9.91E37 with event
2225, as the scopes answer; a source that is off is 2244; a source at the converter's rail
gives its value with the clipping warning (547, 548 or 549). The 4 Series adds
``MEASUrement:ADDMEAS`` and the current acquisition's ``RESUlts``."""
from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from ..devices.oscilloscope import CODE_MAX, CODE_MIN
from ..scpi.engine import Call, Word
from ..scpi.status import ScpiError
from .commands import CHANNEL_WORDS
from .waveform_commands import source_waveform

NO_VALUE = 9.91e37  # what a Tek scope answers for a measurement it cannot make
# the warnings of a measurement on a clipped source (the manuals' event codes): 547 clipping
# positive/negative, 548 clipping positive, 549 clipping negative
CLIPPING = {(True, True): 547, (True, False): 548, (False, True): 549}
SLOTS = 8
MEASUREMENTS: dict[str, Callable[[np.ndarray], Any]] = {
    "AMPlitude": lambda v: v.max() - v.min(), "PK2pk": lambda v: v.max() - v.min(),
    "MAXimum": np.max, "MINimum": np.min, "HIGH": np.max, "LOW": np.min, "MEAN": np.mean,
    "RMS": lambda v: np.sqrt(np.mean(v * v))}


def default_slots(channel: str) -> dict:
    """{slot: {"type", "source", "state"}}: "IMMed" and 1..8, AMPlitude of ``channel``."""
    return {slot: {"type": "AMPlitude", "source": channel, "state": slot == "IMMed"}
            for slot in ("IMMed", *range(1, SLOTS + 1))}


def register(tree, scope) -> None:
    """Add the measurement commands of ``scope`` (a VirtualScope) to a command tree."""
    p = scope.personality

    def slot(c: Call) -> dict:
        if not c.suffixes or c.suffixes[1] is None:
            return scope.measurements["IMMed"]
        if not 1 <= c.suffixes[1] <= SLOTS:
            raise ScpiError(-113, f"{c.header}: MEAS1 to MEAS{SLOTS}")
        return scope.measurements[c.suffixes[1]]

    def setter(field: str, choices):
        def write(c: Call):
            slot(c)[field] = c.word(choices)
        return write

    def value(c: Call) -> str:
        m = slot(c)
        codes, pre, _ = source_waveform(scope, m["source"], c.header)
        if codes is None:
            scope.status.post(2225, c.header)
            return p.number(NO_VALUE)
        v = pre.y_zero + pre.y_multiplier * (codes.astype(np.float64) - pre.y_offset)
        top, bottom = bool(np.any(codes >= CODE_MAX)), bool(np.any(codes <= CODE_MIN))
        if top or bottom:  # the value stands, with the warning the scopes give for a clipped source
            scope.status.post(CLIPPING[top, bottom], c.header)
        return p.number(float(MEASUREMENTS[m["type"]](v)))

    def set_state(c: Call):
        slot(c)["state"] = c.boolean()

    for node in ("IMMed", "MEAS<n>"):
        tree.add(f"MEASUrement:{node}:TYPe", write=setter("type", tuple(MEASUREMENTS)),
                 read=lambda c: Word(slot(c)["type"]))
        tree.add(f"MEASUrement:{node}:SOUrce<n>", write=setter("source", CHANNEL_WORDS),
                 read=lambda c: Word(slot(c)["source"]))
        tree.add(f"MEASUrement:{node}:VALue", read=value)
        tree.add(f"MEASUrement:{node}:UNIts", read=lambda c: '"V"')
    tree.add("MEASUrement:MEAS<n>:STATE", write=set_state, read=lambda c: "1" if slot(c)["state"] else "0")
    if p.name == "mso4":
        register_results(tree, scope, slot, value)


def register_results(tree, scope, slot, value) -> None:
    """The 4 Series' way: ``MEASUrement:ADDMEAS <type>`` switches on the first slot that is
    off with that type (on DATa:SOUrce's channel), and ``MEASUrement:MEAS<x>:RESUlts:
    CURRentacq:<statistic>?`` gives the statistics of the current acquisition's one value:
    MEAN, MAXimum and MINimum the value, PK2PK and STDDev 0, POPUlation 1."""
    p = scope.personality

    def add(c: Call):
        kind = c.word(tuple(MEASUREMENTS))
        free = next((n for n in range(1, SLOTS + 1) if not scope.measurements[n]["state"]), None)
        if free is None:
            raise ScpiError(-221, f"{c.header} {c.arg().text}: all {SLOTS} measurements are on")
        scope.measurements[free] = {"type": kind, "source": scope.data.source, "state": True}

    tree.add("MEASUrement:ADDMEAS", write=add)
    for stat in ("MEAN", "MAXimum", "MINimum"):
        tree.add(f"MEASUrement:MEAS<n>:RESUlts:CURRentacq:{stat}", read=value)

    def spread(c: Call) -> str:
        v = value(c)
        return v if float(v) >= NO_VALUE else p.number(0.0)

    for stat in ("PK2PK", "STDDev"):
        tree.add(f"MEASUrement:MEAS<n>:RESUlts:CURRentacq:{stat}", read=spread)
    tree.add("MEASUrement:MEAS<n>:RESUlts:CURRentacq:POPUlation",
             read=lambda c: "0" if float(value(c)) >= NO_VALUE else "1")
