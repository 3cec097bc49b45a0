"""Measurements on the last record (programmer manuals, "Measurement" command group):
the immediate one, ``MEASUrement:IMMed:TYPe/SOUrce/VALue?/UNIts?``, and the numbered slots
``MEASUrement:MEAS<n>:TYPe/SOUrce/STATE/VALue?/UNIts?`` (n = 1..8; ``SOUrce`` is ``SOUrce1``, the
waveform measured, ``SOUrce2`` the second waveform of a delay or phase measurement, kept
apart and read by none of the measurements emulated), each model with its
manual's words (MEASUREMENTS, SPELLINGS): AMPlitude and PK2pk (max - min: the min-max
method of HIGH and LOW), MAXimum, MINimum, HIGH, LOW, MEAN, RMS in volts; FREQuency,
PERIod (the first cycle: two rising crossings of the 50% mid reference), PWIdth, NWIdth,
RISe and FALL (10-90%) in seconds and hertz; CMEan and CRMs over the first cycle. A figure
the record does not allow is 9.91E37 with Tek's event (2202 "No period found", 2209 "No
second Mid Ref crossing", ...). Without a record the value is 9.91E37 with event 2225, as
the scopes answer; a source that is off is 2244 (the TDS2000: 9.91E37 and 2225, as its
manual says); a source at the converter's rail gives its value with the clipping warning
(547, 548 or 549). The 4 Series adds ``MEASUrement:ADDMEAS``, ``MEASUrement:LIST?`` and the
current acquisition's ``RESUlts``."""
from __future__ import annotations

import math
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
class NotMeasured(Exception):
    """A measurement the record does not allow: the Tek event code it posts (its words are
    the status model's)."""

    def __init__(self, code: int) -> None:
        super().__init__(code)
        self.code = code


HYSTERESIS = 0.1
"""A crossing of a reference level counts where the signal goes from below the level less
this fraction of the amplitude to above the level plus it (or the other way): a noise
ripple on an edge is no second crossing, as the scopes' measurement hysteresis has it."""


def crossings(v: np.ndarray, level: float, rising: bool, band: float = 0.0) -> np.ndarray:
    """Sample positions (fractional, linear between samples) where ``v`` crosses ``level``
    upwards (``rising``) or downwards, with hysteresis: a crossing is the last one of the
    level on the way from below level - band to above level + band (or back)."""
    state = np.where(v <= level - band, -1, np.where(v >= level + band, 1, 0))
    decisive = np.flatnonzero(state)
    if decisive.size < 2:
        return np.zeros(0)
    d = state[decisive]
    flips = np.flatnonzero(d[1:] != d[:-1]) + 1
    out = []
    for f in flips.tolist():
        if (d[f] == 1) != rising:
            continue
        a, b = int(decisive[f - 1]), int(decisive[f])
        seg = v[a:b + 1]
        through = (seg[:-1] < level) & (seg[1:] >= level) if rising else (seg[:-1] > level) & (seg[1:] <= level)
        k = np.flatnonzero(through)
        i = a + int(k[-1])
        out.append(i + (level - v[i]) / (v[i + 1] - v[i]))
    return np.array(out)


def levels(v: np.ndarray) -> tuple:
    """(low, high) by the min-max method (MEASUrement:METHod MINMax) and the 10, 50, 90%
    reference levels between them."""
    low, high = float(v.min()), float(v.max())
    return low, high, *(low + f * (high - low) for f in (0.1, 0.5, 0.9))


def first_cycle(v: np.ndarray) -> tuple:
    """(start, end) sample positions of the first cycle: two rising crossings of the mid
    reference; NotMeasured 2202 "No period found" without two."""
    low, high, _, mid, _ = levels(v)
    up = crossings(v, mid, True, HYSTERESIS * (high - low))
    if up.size < 2:
        raise NotMeasured(2202)
    return float(up[0]), float(up[1])


def period(v: np.ndarray, dt: float) -> float:
    """Time of the first cycle (s)."""
    a, b = first_cycle(v)
    return (b - a) * dt


def width(v: np.ndarray, dt: float, positive: bool) -> float:
    """Time (s) from the first mid-reference crossing up (positive) or down to the next one
    the other way."""
    low, high, _, mid, _ = levels(v)
    band = HYSTERESIS * (high - low)
    first = crossings(v, mid, positive, band)
    if first.size == 0:
        raise NotMeasured(2213 if positive else 2212)
    back = crossings(v, mid, not positive, band)
    back = back[back > first[0]]
    if back.size == 0:
        raise NotMeasured(2209)
    return float(back[0] - first[0]) * dt


def edge(v: np.ndarray, dt: float, rising: bool) -> float:
    """Rise (10% to 90%) or fall (90% to 10%) time (s) of the first such edge."""
    low, high, p10, _, p90 = levels(v)
    band = 0.5 * HYSTERESIS * (high - low)  # half the mid reference's: the 10% level lies 10% above the base
    far = crossings(v, p90 if rising else p10, rising, band)
    if far.size == 0:
        raise NotMeasured(2213 if rising else 2212)
    near = crossings(v, p10 if rising else p90, rising, band)
    near = near[near <= far[0]]
    if near.size == 0:
        raise NotMeasured(2211)
    return float(far[0] - near[-1]) * dt


def over_cycle(v: np.ndarray, f) -> float:
    """``f`` (mean, rms) of the samples of the first cycle."""
    a, b = first_cycle(v)
    return float(f(v[int(math.ceil(a)):int(math.floor(b)) + 1]))


MEASUREMENTS: dict[str, Callable[[np.ndarray, float], Any]] = {
    "AMPlitude": lambda v, dt: v.max() - v.min(), "PK2pk": lambda v, dt: v.max() - v.min(),
    "MAXimum": lambda v, dt: v.max(), "MINimum": lambda v, dt: v.min(), "HIGH": lambda v, dt: v.max(),
    "LOW": lambda v, dt: v.min(), "MEAN": lambda v, dt: v.mean(), "RMS": lambda v, dt: np.sqrt(np.mean(v * v)),
    "FREQuency": lambda v, dt: 1.0 / period(v, dt), "PERIod": period,
    "PWIdth": lambda v, dt: width(v, dt, True), "NWIdth": lambda v, dt: width(v, dt, False),
    "RISe": lambda v, dt: edge(v, dt, True), "FALL": lambda v, dt: edge(v, dt, False),
    "CMEan": lambda v, dt: over_cycle(v, np.mean),
    "CRMs": lambda v, dt: over_cycle(v, lambda x: np.sqrt(np.mean(x * x))),
}
"""The measurements (volts, or seconds and hertz for the timing ones: Tek's definitions on
the min-max levels, mid reference 50%, edges 10-90%)."""
SPELLINGS = {
    "tds2000": {"FREQuency": "FREQuency", "MEAN": "MEAN", "PERIod": "PERIod", "PK2pk": "PK2pk", "CRMs": "CRMs",
                "MINImum": "MINimum", "MAXImum": "MAXimum", "RISe": "RISe", "FALL": "FALL", "PWIdth": "PWIdth",
                "NWIdth": "NWIdth"},
    "mso4": {**{k: k for k in MEASUREMENTS if k not in ("RISe", "FALL")}, "RISETIME": "RISe", "FALLTIME": "FALL"},
}
"""{personality: {word of its manual: measurement}} where its words differ (the TDS2000's
eleven; the 4 Series' RISETIME and FALLTIME); the others take MEASUREMENTS' words."""
UNITS = {"FREQuency": "Hz", "PERIod": "s", "PWIdth": "s", "NWIdth": "s", "RISe": "s", "FALL": "s"}


def words_of(personality: str) -> dict:
    """{word the model takes: measurement} of a personality."""
    return SPELLINGS.get(personality, {k: k for k in MEASUREMENTS})


SECOND_SOURCE = "CH2"
"""SOUrce2 of every slot until set: the waveform a delay or phase measurement would measure
"to" (none of the emulated measurements reads it)."""


def default_slots(channel: str, personality: str = "") -> dict:
    """{slot: {"type", "source", "source2", "state"}}: "IMMed" and 1..8, of ``channel``:
    PK2pk on the TDS2000 (whose manual has no AMPlitude), AMPlitude on the others; only
    IMMed on. ``source`` is SOUrce1 (SOUrce), the one the measurements read; ``source2``
    SOUrce2, kept apart (the MDO3000 manual, MEASUrement:MEAS<x>:SOUrce1: "For SOUrce2: ...
    the waveform to measure 'to' when taking a delay measurement or phase measurement")."""
    kind = "PK2pk" if personality == "tds2000" else "AMPlitude"
    return {slot: {"type": kind, "source": channel, "source2": SECOND_SOURCE, "state": slot == "IMMed"}
            for slot in ("IMMed", *range(1, SLOTS + 1))}


def source_field(c: Call) -> str:
    """The slot's field a MEASUrement:...:SOUrce<n> header names: SOUrce and SOUrce1 the
    measured waveform, SOUrce2 the second one; another number is an undefined header."""
    n = c.suffixes[-1]
    if n not in (None, 1, 2):
        raise ScpiError(-113, f"{c.header}: SOUrce1 or SOUrce2")
    return "source2" if n == 2 else "source"


def register(tree, scope) -> None:
    """Add the measurement commands of ``scope`` (a VirtualScope) to a command tree."""
    p = scope.personality

    def slot(c: Call) -> dict:
        if not c.suffixes or c.suffixes[1] is None:
            return scope.measurements["IMMed"]
        if not 1 <= c.suffixes[1] <= SLOTS:
            raise ScpiError(-113, f"{c.header}: MEAS1 to MEAS{SLOTS}")
        return scope.measurements[c.suffixes[1]]

    words = words_of(p.name)

    def set_source(c: Call):
        slot(c)[source_field(c)] = c.word(CHANNEL_WORDS)

    def set_type(c: Call):
        slot(c)["type"] = words[c.word(tuple(words))]

    def read_type(c: Call) -> Word:
        kind = slot(c)["type"]
        return Word(next(w for w, k in words.items() if k == kind))

    def value(c: Call) -> str:
        m = slot(c)
        if p.name == "tds2000" and m["source"] not in scope.shown:  # the TDS manual: 9.9E37, event 2225
            scope.status.post(2225, f"{m['source']} is off; {c.header}")
            return p.number(NO_VALUE)
        codes, pre, _ = source_waveform(scope, m["source"], c.header)
        if codes is None:
            scope.status.post(2225, c.header)
            return p.number(NO_VALUE)
        v = pre.y_zero + pre.y_multiplier * (codes.astype(np.float64) - pre.y_offset)
        top, bottom = bool(np.any(codes >= CODE_MAX)), bool(np.any(codes <= CODE_MIN))
        if top or bottom:  # the value stands, with the warning the scopes give for a clipped source
            scope.status.post(CLIPPING[top, bottom], c.header)
        try:
            return p.number(float(MEASUREMENTS[m["type"]](v, pre.x_increment)))
        except NotMeasured as e:
            scope.status.post(e.code, c.header)
            return p.number(NO_VALUE)

    def set_state(c: Call):
        slot(c)["state"] = c.boolean()

    for node in ("IMMed", "MEAS<n>"):
        tree.add(f"MEASUrement:{node}:TYPe", write=set_type, read=read_type)
        tree.add(f"MEASUrement:{node}:SOUrce<n>", write=set_source, read=lambda c: Word(slot(c)[source_field(c)]))
        tree.add(f"MEASUrement:{node}:VALue", read=value)
        tree.add(f"MEASUrement:{node}:UNIts", read=lambda c: f'"{UNITS.get(slot(c)["type"], "V")}"')
    tree.add("MEASUrement:MEAS<n>:STATE", write=set_state, read=lambda c: "1" if slot(c)["state"] else "0")
    if p.name == "mso4":
        register_results(tree, scope, slot, value)


def register_results(tree, scope, slot, value) -> None:
    """The 4 Series' way: ``MEASUrement:ADDMEAS <type>`` switches on the first slot that is
    off with that type (on DATa:SOUrce's channel), ``MEASUrement:LIST?`` names the slots on
    (NONE), and ``MEASUrement:MEAS<x>:RESUlts:CURRentacq:<statistic>?`` gives the statistics
    of the current acquisition's one value: MEAN, MAXimum and MINimum the value, PK2PK and
    STDDev 0, POPUlation 1; of a slot that is off, 9.91E37 with event 2225."""
    p = scope.personality

    words = words_of(p.name)

    def add(c: Call):
        kind = words[c.word(tuple(words))]
        free = next((n for n in range(1, SLOTS + 1) if not scope.measurements[n]["state"]), None)
        if free is None:
            raise ScpiError(-221, f"{c.header} {c.arg().text}: all {SLOTS} measurements are on")
        scope.measurements[free] = {**scope.measurements[free], "type": kind, "source": scope.data.source,
                                    "state": True}

    def result(c: Call) -> str:
        """A slot's value, if the slot is on: one that is off has no results (9.91E37, 2225)."""
        if not slot(c)["state"]:
            scope.status.post(2225, f"MEAS{c.suffixes[1]} is off (MEASUrement:ADDMEAS adds one); {c.header}")
            return p.number(NO_VALUE)
        return value(c)

    tree.add("MEASUrement:ADDMEAS", write=add)
    tree.add("MEASUrement:LIST", read=lambda c: ",".join(
        f"MEAS{n}" for n in range(1, SLOTS + 1) if scope.measurements[n]["state"]) or "NONE")
    for stat in ("MEAN", "MAXimum", "MINimum"):
        tree.add(f"MEASUrement:MEAS<n>:RESUlts:CURRentacq:{stat}", read=result)

    def spread(c: Call) -> str:
        v = result(c)
        return v if float(v) >= NO_VALUE else p.number(0.0)

    for stat in ("PK2PK", "STDDev"):
        tree.add(f"MEASUrement:MEAS<n>:RESUlts:CURRentacq:{stat}", read=spread)
    tree.add("MEASUrement:MEAS<n>:RESUlts:CURRentacq:POPUlation",
             read=lambda c: "0" if float(result(c)) >= NO_VALUE else "1")
