"""The command lists of the emulated models' programmer manuals (manuals/: the MDO3000's and
the 4 Series' written by tools/manual_commands.py from the command trees of tm_devices, which
Tektronix generates from the manuals; the TDS2000's, which has no such tree, transcribed by
hand from its manual, 071-1075): each header with its query and set forms and the words its
set form takes. The scope refuses a word of its manual that it does not emulate as a setting it does
not model (221 "Settings conflict"), not as one it has never heard of (224); coverage.py
measures the emulation against these lists."""
from __future__ import annotations

import re
from dataclasses import dataclass
from functools import cache
from importlib import resources

from ..errors import InstrumentError
from ..scpi.tree import Mnemonic

MODELS = ("tds2000", "mdo3000", "mso4")
LETTERED = {"tds2000"}  # models whose reference waveforms are REFA to REFD (the manual's REF<x>), not REF1 to REF4
ENUM = re.compile(r"\{([^{}]*)\}")
WORD = re.compile(r"[A-Za-z0-9_]+(<x>[A-Za-z0-9_]*)?")  # a word of an enumeration (CH<x>: a numbered one)


@dataclass(frozen=True)
class ManualCommand:
    """One header of a manual: its group, the header as the manual spells it, whether it
    has a query form and a set form, and the set form's argument syntax."""

    group: str
    header: str
    query: bool
    write: bool
    args: str = ""
    lettered: bool = False  # REF<x> is REFA to REFD (LETTERED)

    @property
    def concrete(self) -> str:
        """The header with every <x> taken as 1 (REF<x> as REFA where ``lettered``) and every
        {A|B} choice as its first."""
        header = self.header.replace("REF<x>", "REFA") if self.lettered else self.header
        return ENUM.sub(lambda m: m.group(1).split("|")[0], header.replace("<x>", "1"))

    @property
    def words(self) -> tuple:
        """The enumerated words the set form takes (``{DC|AC|GND}``), in the manual's order."""
        m = ENUM.search(self.args)
        return tuple(w for w in m.group(1).split("|") if WORD.fullmatch(w)) if m else ()


@cache
def manual(model: str) -> tuple:
    """The ManualCommands of a model's manual, in the file's order (one per header)."""
    if model not in MODELS:
        raise InstrumentError(f"model = {model!r}: allowed {', '.join(MODELS)}")
    text = resources.files(__package__).joinpath("manuals").joinpath(f"{model}.txt").read_text(encoding="utf-8")
    heads: dict = {}
    for line in text.splitlines():
        if not line or line.startswith("#"):
            continue
        group, syntax = line.split("\t", 1)
        head, _, args = syntax.partition(" ")
        query = head.endswith("?")
        head = head.rstrip("?")
        old = heads.get(head, ManualCommand(group, head, False, False))
        heads[head] = ManualCommand(group, head, old.query or query, old.write or not query,
                                    old.args or ("" if query else args), model in LETTERED)
    return tuple(heads.values())



def normal(header: str) -> str:
    """A header as a key: long form, capitals, no leading colon, no numeric suffix (<x>)."""
    parts = (re.sub(r"<x>|\d+$", "", p, flags=re.I) for p in header.strip(":").split(":"))
    return ":".join(Mnemonic(p).long if p and not p.startswith("*") else p.upper() for p in parts)


@cache
def words_of(model: str) -> dict:
    """{normal(header): the words of its set form, as the manual prints them} of a model
    ({} for a model without a list here)."""
    if model not in MODELS:
        return {}
    return {normal(c.header): c.words for c in manual(model) if c.words}


def in_manual(model: str, header: str, word: str) -> bool:
    """Whether ``word`` (as a client sent it, long or short form) is one the model's manual
    lists for ``header`` (as found in the emulation's tree, e.g. ``:CH1:COUPLING``)."""
    text = word.upper()
    for w in words_of(model).get(normal(header), ()):
        stem, numbered = w.split("<")[0], "<" in w  # MATH<x>: MATH1, MATH2, ...
        bare = re.sub(r"\d+$", "", text) if numbered else text
        if stem and bare in (Mnemonic(stem).long, Mnemonic(stem).short):
            return True
    return False
