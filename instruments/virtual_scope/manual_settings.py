"""The rest of a model's manual that a waveform program meets, each registered only where
the model's manual (manual.py) lists it:

- **Group queries.** A header the manual gives as a query alone whose settings the tree
  holds (``CH<x>?``, ``HORizontal?``, ``HORizontal:MAIn?``, ``ACQuire?``, ...) answers
  them all in one reply, as the manuals' group queries do: ``:CH1:SCALE 5.0E-2;POSITION
  0.0E0;...`` with HEADer on, ``5.0E-2;0.0E0;...`` with it off; its settings in the order
  the emulation registers them (the manuals' texts do not give the reply's order), each
  answered as its own query answers it, once (not again under another name, the TDS2000's
  ``VOLts``); a result (a query alone, ``VALue``), the settings beneath a setting
  (``CH<x>:PRObe:GAIN``), or a numbered one (``MEAS<x>``) is left out.
- ``ID?``: ``TEK/<model>,CF:91.1CT,FV:<version>`` from ``*IDN?`` (the TDS2000 and MDO3000
  manuals' form).
- ``LOCk {ALL|NONe}``, ``UNLock ALL``: the front panel's lock, kept and answered (the
  emulated scope has no front panel to lock); ``REM <QString>``: a comment, nothing done.
- ``FACtory``: the factory set-up, as ``*RST`` and ``RECAll:SETUp FACtory`` give it.
- ``ACQuire:MAXSamplerate?`` (MDO3000): the model's real-time rate, as
  ``CONFIGuration:ANALOg:MAXSAMPLERate?`` answers it.
- ``TRIGger:A:HOLDoff:TIMe`` (0 to 10 s, the manuals' range; 0 s until set, the manuals
  giving no factory value): kept and answered. The holdoff keeps the trigger from re-arming
  for that long after a trigger; an emulated acquisition ends at its first trigger, so it
  changes no record.
- Settings taken at the one value that is emulated, any other of the manual's values
  refused with 221 "not modelled" (never taken and then ignored): ``CH<x>:INVert OFF``,
  ``CH<x>:YUNit "V"`` (the gauges are read in volts; current probes are not modelled),
  ``CH<x>:IMPedance MEG`` (1 MOhm, the input the gauges' RC filter is computed for),
  ``SELect:MATH OFF`` and ``SELect:REF<x> OFF`` (no math or reference waveforms),
  ``HORizontal:VIEW MAIn`` (no zoom window), ``CH<x>:PROBEFunc:EXTAtten 1`` (no external
  attenuator: the probe's own attenuation is ``CH<x>:PRObe``)."""
from __future__ import annotations

from ..scpi.engine import Call, Fields, Word
from ..scpi.status import ScpiError
from .configuration import max_sample_rate
from .manual import MODELS, manual, normal

ONE_VALUE = {  # header: (the emulated value's word, string or number, how the manual's syntax writes the set form)
    "CH<x>:INVert": ("OFF", "word"), "CH<x>:YUNit": ('"V"', "string"), "CH<x>:IMPedance": ("MEG", "word"),
    "SELect:MATH": ("0", "switch"), "SELect:REF<x>": ("0", "switch"), "HORizontal:VIEW": ("MAIn", "word"),
    "CH<x>:PROBEFunc:EXTAtten": ("1.0", "number"),
}
IMPEDANCE_OHM = 1e6
EXTERNAL_ATTENUATION = (1e-10, 1e10)  # CH<x>:PROBEFunc:EXTAtten's range (4 Series manual), a multiplier
HOLDOFF_S = (0.0, 10.0)  # TRIGger:A:HOLDoff:TIMe's range (MDO3000 and 4 Series manuals), s
UNITS = ("V", "A")  # CH<x>:YUNit's strings (TDS1000B/2000B: volts, or amperes with a current probe)


def register(tree, scope) -> None:
    """Add what the module doc lists to the tree of ``scope`` (a VirtualScope), where its
    model's manual has it and the tree does not hold it yet; group queries last."""
    model = scope.personality.name
    if model not in MODELS:
        return
    listed = {normal(c.header): c for c in manual(model)}

    def add(header: str, **handlers) -> None:
        command = listed.get(normal(header))
        if command is None:
            return
        lettered = command.lettered and "REF<x>" in header
        for pattern in [header.replace("REF<x>", f"REF{x}") for x in "ABCD"] if lettered else [header]:
            if tree.find(tokens(pattern)) is None:
                tree.add(pattern.replace("<x>", "<n>"), **handlers)

    idn = scope.personality.idn.split(",")
    version = ",".join(idn[3].split()) if len(idn) > 3 else ""
    add("ID", read=lambda c: f"TEK/{idn[1].strip() if len(idn) > 1 else ''},{version}".rstrip(","))
    lock = {"state": "NONe"}

    def set_lock(c: Call):
        lock["state"] = c.word(("ALL", "NONe"))

    def unlock(c: Call):
        c.word(("ALL",))
        lock["state"] = "NONe"

    add("LOCk", write=set_lock, read=lambda c: Word(lock["state"]))
    add("UNLock", write=unlock)
    add("REM", write=comment)
    add("FACtory", write=lambda c: scope.reset())
    holdoff = {"s": HOLDOFF_S[0]}

    def set_holdoff(c: Call):
        t = c.number("S")
        if not HOLDOFF_S[0] <= t <= HOLDOFF_S[1]:
            raise ScpiError(-222, f"{c.header} {t:g} s: allowed 0 to 10 s")
        holdoff["s"] = t

    add("TRIGger:A:HOLDoff:TIMe", write=set_holdoff, read=lambda c: scope.personality.number(holdoff["s"]))
    rate = max_sample_rate(scope.personality)
    if rate is not None:
        add("ACQuire:MAXSamplerate", read=lambda c: scope.personality.number(rate))
    for header, (value, form) in ONE_VALUE.items():
        words = listed[normal(header)].words if normal(header) in listed else ()
        add(header, write=one_value(words, value, form), read=lambda c, v=value, f=form: answer(scope, v, f))
    for command in manual(model):  # the group queries, once their settings are in the tree
        if command.query and not command.write and not command.args and "{" not in command.header:
            node = group_node(tree, command.header)
            if node is not None and tree.find(tokens(command.header)) is None:
                tree.add(command.header.replace("<x>", "<n>"), read=group_query(node))


def tokens(header: str) -> tuple:
    """A manual header as the tree's find() takes it: its long forms (capitals), <x> as 1."""
    return tuple(part.replace("<x>", "1").upper() for part in header.split(":"))


def comment(c: Call) -> None:
    """REM: a comment in a program, its string read and nothing done."""
    c.taken[0] = len(c.args)


def answer(scope, value: str, form: str):
    """A one-value setting's query answer: a word in the reply form, a number in the
    model's NR3, a string or a switch as it is."""
    if form == "word":
        return Word(value)
    return scope.personality.number(float(value)) if form == "number" else value


def one_value(words: tuple, value: str, form: str):
    """The set form of a setting emulated at ``value`` only: that value taken, any other
    of the manual's refused with 221 (one of no manual's: 224, by the engine)."""
    def write(c: Call):
        a = c.arg()
        if form == "switch":
            taken = not c.boolean()
        elif form == "string":
            unit = a.text.strip("\"'").upper()
            if unit not in UNITS:
                raise ScpiError(-224, f"{c.header} {a.text[:40]}: allowed {', '.join(UNITS)}")
            taken = unit == value.strip('"')
        elif form == "number":  # CH<x>:PROBEFunc:EXTAtten <NR3>
            x = c.number()
            if not EXTERNAL_ATTENUATION[0] <= x <= EXTERNAL_ATTENUATION[1]:
                raise ScpiError(-222, f"{c.header} {x:g}: allowed 1E-10 to 1E10")
            taken = x == float(value)
        elif a.kind == "number":  # CH<x>:IMPedance <NR3>: ohms
            taken = c.number("OHM") == IMPEDANCE_OHM
        else:
            taken = Word(c.word(words)).form(True) == Word(value).form(True)
        if not taken:
            raise ScpiError(-221, f"{c.header} {a.text[:40]}: in the manual, not modelled here (only "
                                  f"{value.strip(chr(34))})")
    return write


def group_node(tree, header: str):
    """The tree's node of a manual header that has settings beneath it, or None."""
    node = tree.root
    for token in tokens(header):
        node = next((child for child in node.children if child.mnemonic.match(token, False) is not False), None)
        if node is None:
            return None
    return node if any(leaf(child) for child in node.children) else None


def leaf(node) -> bool:
    """A setting a group query answers: set and queried on its own, not numbered (a result,
    query only, is not a setting: MEASUrement:MEAS<x>:VALue)."""
    c = node.command
    return c is not None and c.read is not None and c.write is not None and not node.mnemonic.numbered


def group_query(node):
    """The read handler of a group query: Fields of the settings beneath ``node``."""
    def read(c: Call):
        pairs, seen = [], set()
        for child in node.children:
            if not leaf(child) or child.command.read in seen:  # another name of a setting answered (VOLts)
                continue
            seen.add(child.command.read)
            try:
                value = child.command.read(Call((), c.suffixes + (None,), f"{c.header}:{child.mnemonic.long}",
                                                c.context))
            except ScpiError:
                continue  # a setting this model or channel does not answer now
            if not isinstance(value, Fields):
                pairs.append((child.mnemonic.spec, value))
        if not pairs:
            raise ScpiError(-200, f"{c.header}?: nothing to answer")
        return Fields(tuple(pairs))
    return read
