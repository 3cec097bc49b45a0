"""The emulated scope's front panel over SCPI: vertical, horizontal, trigger, acquisition
and which channels are on (TDS2000 and MDO3000 programmer manuals, command groups of the
same names). Each setting is the scene key it overrides; V/div and s/div are snapped to
the model's 1-2-5 (TDS s/div: 1-2.5-5) steps, the record length to the model's list (a
length it cannot take is an execution error), and a value the oscilloscope refuses is
-222 (data out of range) or -221 (settings conflict) with its reason. Not emulated, and
refused with -221: GND coupling, trigger couplings other than DC, acquisition modes other
than sample and average, roll mode. ``AUTOSet`` is a documented no-op (the scene sets the
scope). The horizontal group is horizontal.py's."""
from __future__ import annotations

import math

from ..devices.scope_settings import LEVEL_LIMIT_V
from ..scpi.engine import Call, Fields, Word
from ..scpi.status import ScpiError
from .personalities import snap_to_steps
from .settings import channel_key

CHANNEL_WORDS = ("CH1", "CH2", "CH3", "CH4")
TWENTY_MHZ = 20e6
LOGIC_LEVELS = {"ECL": -1.3, "TTL": 1.4}  # TRIGger:A:LEVel's preset words (MDO3000, DPO4000 manuals), V


def trigger_state(scope) -> str:
    """TRIGger:STATE? in the manuals' words: SAVe while no acquisition is under way
    ("acquisition is stopped"); AUTO while acquiring in AUTO mode with the last record taken
    untriggered ("in the automatic mode and acquires data even in the absence of a
    trigger"); READy while acquiring otherwise (the pretrigger taken, waiting for a trigger)."""
    if not scope.acq.acquiring:
        return "SAVe"
    last = scope.acq.last
    untriggered = last is not None and bool(last.record.waveforms) and not last.record.triggered
    return "AUTO" if untriggered and scope.settings["scope.trigger.mode"] == "auto" else "READy"


def register(tree, scope) -> None:
    """Add the front-panel commands of ``scope`` (a VirtualScope) to a command tree."""
    p = scope.personality

    def num(key):
        return lambda c: p.number(scope.settings[key])

    def channel(c: Call, field: str) -> str:
        if not 1 <= c.suffix <= 4:
            raise ScpiError(-113, f"{c.header}: channels CH1 to CH4")
        return channel_key(f"CH{c.suffix}", field)

    def set_channel(field, convert):
        return lambda c: scope.change({channel(c, field): convert(c)}, code=-222)

    def volts_per_div(c: Call) -> float:
        return snap_to_steps(positive(c, c.number("V")), p.volt_steps)

    def coupling(c: Call) -> str:
        word = c.word(("DC", "AC", "GND"))
        if word == "GND":
            raise ScpiError(-221, f"{c.header} GND: not emulated (DC or AC)")
        return word

    def bandwidth(c: Call):
        a = c.arg()
        if a.kind == "number":
            return positive(c, c.number("HZ"))
        return {"ON": TWENTY_MHZ, "TWEnty": TWENTY_MHZ, "OFF": None, "FULl": None}[
            c.word(("ON", "OFF", "TWEnty", "FULl"))]

    def read_bandwidth(c: Call):
        bw = scope.settings[channel(c, "bandwidth")]
        if p.name == "tds2000":
            return Word("ON" if bw is not None and bw <= TWENTY_MHZ else "OFF")
        return Word("FULl") if bw is None else p.number(bw)

    for field, convert in (("volts_per_div", volts_per_div), ("position", lambda c: c.number()),
                           ("offset", lambda c: c.number("V")), ("coupling", coupling),
                           ("bandwidth", bandwidth), ("probe", lambda c: c.number())):
        name = {"volts_per_div": "SCAle", "position": "POSition", "offset": "OFFSet", "coupling": "COUPling",
                "bandwidth": "BANdwidth", "probe": "PRObe"}[field]
        read = {"coupling": lambda c: Word(scope.settings[channel(c, "coupling")]),
                "bandwidth": read_bandwidth}.get(field, lambda c, f=field: p.number(scope.settings[channel(c, f)]))
        tree.add(f"CH<n>:{name}", write=set_channel(field, convert), read=read)
    tree.add("CH<n>:PRObe:GAIN", write=set_channel("probe", lambda c: 1.0 / positive(c, c.number())),
             read=lambda c: p.number(1.0 / scope.settings[channel(c, "probe")]))  # MDO form: gain = 1 / attenuation

    def refuse_but(allowed: str):
        """A setting that takes one value only (what is emulated); others are -221."""
        def write(c: Call):
            if c.arg().text.upper() not in (Word(allowed).form(True), Word(allowed).form(False)):
                raise ScpiError(-221, f"{c.header} {c.arg().text}: only {allowed} is emulated")
        return write

    tree.add("HORizontal:MAIn:UNIts", read=lambda c: '"s"')
    tree.add("HORizontal:ROLL", write=refuse_but("OFF"), read=lambda c: Word("OFF"))

    # --- trigger ----------------------------------------------------------------------
    def force(c: Call):
        c.word(("FORCe",))
        scope.acq.force()

    tree.add("TRIGger", write=force)
    tree.add("TRIGger:STATE", read=lambda c: Word(trigger_state(scope)))
    def set_source(c: Call):
        """The edge trigger's source; the level follows the channel's own where a client set
        one (TRIGger:A:LEVel:CH<x>), as each channel keeps its level on the scopes."""
        ch = c.word(CHANNEL_WORDS)
        own = scope.trigger_levels.get(ch)
        scope.change({"scope.trigger.source": ch, **({} if own is None else {"scope.trigger.level": own})})

    def level_channel(c: Call) -> str:
        """The channel a TRIGger:A:LEVel header is about: CH<x>'s, or the trigger's source."""
        ch = f"CH{c.suffix}" if c.suffixes and c.suffixes[-1] is not None else scope.settings["scope.trigger.source"]
        if ch not in CHANNEL_WORDS:
            raise ScpiError(-113, f"{c.header}: channels CH1 to CH4")
        return ch

    def set_level(c: Call):
        """TRIGger:A:LEVel (the source's) or TRIGger:A:LEVel:CH<x> (channel x's; the
        trigger's own where x is its source), V, or the manuals' ECL (-1.3 V) and TTL (1.4 V)."""
        ch = level_channel(c)
        level = level_value(c)
        if ch == scope.settings["scope.trigger.source"]:
            scope.change({"scope.trigger.level": level}, code=-222)
        elif not abs(level) <= LEVEL_LIMIT_V:
            raise ScpiError(-222, f"{c.header} {c.arg().text}: allowed -{LEVEL_LIMIT_V:g} V to {LEVEL_LIMIT_V:g} V")
        scope.trigger_levels[ch] = level

    def level(c: Call):
        ch = level_channel(c)
        if ch == scope.settings["scope.trigger.source"]:
            return num("scope.trigger.level")(c)
        return p.number(scope.trigger_levels.get(ch, 0.0))

    for head in ("TRIGger:A", "TRIGger:MAIn"):
        tree.add(f"{head}:EDGE:SOUrce", write=set_source, read=lambda c: Word(scope.settings["scope.trigger.source"]))
        tree.add(f"{head}:EDGE:SLOpe", read=lambda c: Word("RISe" if scope.settings["scope.trigger.slope"] == "rising"
                                                           else "FALL"),
                 write=lambda c: scope.change({"scope.trigger.slope": {"RISe": "rising", "FALL": "falling"}[
                     c.word(("RISe", "FALL"))]}))
        tree.add(f"{head}:EDGE:COUPling", write=refuse_but("DC"), read=lambda c: Word("DC"))
        tree.add(f"{head}:TYPe", write=refuse_but("EDGe"), read=lambda c: Word("EDGe"))
        tree.add(f"{head}:READy", read=lambda c: "1" if scope.acq.acquiring else "0")
        tree.add(f"{head}:LEVel", write=set_level, read=level)
        tree.add(f"{head}:LEVel:CH<n>", write=set_level, read=level)

    for head in ("TRIGger:A", "TRIGger:MAIn"):  # the shot's scope.trigger.mode: AUTO takes an untriggered record
        tree.add(f"{head}:MODe", read=lambda c: Word("AUTO" if scope.settings["scope.trigger.mode"] == "auto"
                                                     else "NORMal"),
                 write=lambda c: scope.change({"scope.trigger.mode": c.word(("AUTO", "NORMal")).lower()}))
    if p.name != "tds2000":  # the B trigger of the MDO3000 and 4 Series: its edge settings kept, the B state off
        register_b_trigger(tree, scope)

    # --- acquisition -----------------------------------------------------------------
    def set_state(c: Call):
        a = c.arg()
        on = c.boolean() if a.kind == "number" else c.word(("ON", "OFF", "RUN", "STOP")) in ("ON", "RUN")
        scope.acq.run(on)

    def set_acquire_mode(c: Call):
        mode = c.word(("SAMple", "AVErage", "PEAKdetect", "HIRes", "ENVelope"))
        if mode not in ("SAMple", "AVErage"):
            raise ScpiError(-221, f"{c.header} {c.arg().text}: only SAMple and AVErage are emulated")
        scope.change({"scope.mode": "sample" if mode == "SAMple" else "average",
                      "scope.averages": 1 if mode == "SAMple" else scope.numavg})

    def set_numavg(c: Call):
        n = c.number()
        if not 2 <= n <= 512:
            raise ScpiError(-222, f"{c.header} {c.arg().text}: allowed 2 to 512")
        scope.numavg = 2 ** round(math.log2(n))
        if scope.settings["scope.mode"] == "average":
            scope.change({"scope.averages": scope.numavg})

    tree.add("ACQuire:STATE", write=set_state, read=lambda c: "1" if scope.acq.acquiring else "0")
    tree.add("ACQuire:STOPAfter", write=lambda c: setattr(scope.acq, "stop_after", c.word(("RUNSTop", "SEQuence"))),
             read=lambda c: Word(scope.acq.stop_after))
    tree.add("ACQuire:MODe", write=set_acquire_mode,
             read=lambda c: Word("SAMple" if scope.settings["scope.mode"] == "sample" else "AVErage"))
    tree.add("ACQuire:NUMAVg", write=set_numavg, read=lambda c: str(scope.numavg))
    tree.add("ACQuire:NUMACq", read=lambda c: str(scope.acq.count))

    # --- channels on and off ----------------------------------------------------------
    def show(c: Call):
        ch = f"CH{c.suffix}"
        if ch not in CHANNEL_WORDS:
            raise ScpiError(-113, f"{c.header}: channels CH1 to CH4")
        on = c.boolean()
        scope.change({}, shown=(scope.shown | {ch}) if on else (scope.shown - {ch}))

    def shown(c: Call) -> str:
        return "1" if f"CH{c.suffix}" in scope.shown else "0"

    tree.add("SELect:CH<n>", write=show, read=shown)
    tree.add("SELect", read=lambda c: Fields(tuple((ch, "1" if ch in scope.shown else "0") for ch in CHANNEL_WORDS)))
    tree.add("DISplay:GLObal:CH<n>:STATE", write=show, read=shown)
    tree.add("DISplay:WAVEView<n>:CH<n>:STATE", write=show, read=shown)  # 4/5/6 Series MSO form
    # DISplay:WAVEform (MSO/DPO4000, MDO3000 manuals): the waveforms drawn on the screen or not; the
    # acquisition goes on either way (programs turn it off to transfer faster)
    tree.add("DISplay:WAVEform", write=lambda c: setattr(scope, "display_waveform", c.boolean()),
             read=lambda c: "1" if scope.display_waveform else "0")
    tree.add("AUTOSet", write=lambda c: c.word(("EXECute", "UNDo")) and None)


def level_value(c: Call) -> float:
    """A trigger level's argument (V): a number, or the manuals' ECL and TTL words."""
    return LOGIC_LEVELS[c.word(tuple(LOGIC_LEVELS))] if c.arg().kind != "number" else c.number("V")


def register_b_trigger(tree, scope) -> None:
    """TRIGger:B (the A-then-B sequence): the edge settings of the manual taken and read
    back, TRIGger:B:STATE OFF (ON, the sequence, is not modelled: 221); the record is the A
    trigger's."""
    b = scope.b_trigger

    def keep(field: str):
        def write(c: Call):
            if field == "level":
                b[field] = level_value(c)
            else:
                b[field] = c.word(CHANNEL_WORDS if field == "source" else ("RISe", "FALL"))
        return write

    tree.add("TRIGger:B:EDGE:SOUrce", write=keep("source"), read=lambda c: Word(b["source"]))
    tree.add("TRIGger:B:EDGE:SLOpe", write=keep("slope"), read=lambda c: Word(b["slope"]))
    tree.add("TRIGger:B:EDGE:COUPling", write=lambda c: c.word(("DC",)) and None, read=lambda c: Word("DC"))
    for head in ("TRIGger:B:LEVel", "TRIGger:B:LEVel:CH<n>"):
        tree.add(head, write=keep("level"), read=lambda c: scope.personality.number(b["level"]))
    tree.add("TRIGger:B:TYPe", write=lambda c: c.word(("EDGe",)) and None, read=lambda c: Word("EDGe"))

    def state(c: Call):
        if c.boolean():
            raise ScpiError(-221, f"{c.header} ON: the A-then-B trigger sequence is not modelled (the A trigger's)")

    tree.add("TRIGger:B:STATE", write=state, read=lambda c: "0")


def positive(c: Call, x: float) -> float:
    """x, or -222 naming the header where it is not > 0."""
    if not x > 0:
        raise ScpiError(-222, f"{c.header} {c.arg().text}: a value > 0")
    return x
