"""What the TDS2000's programmer manual (TDS200, TDS1000/TDS2000, TDS1000B/TDS2000B and
TPS2000 Series, 071-1075) gives besides the commands the models share: its other names for
commands the tree holds (``CH<x>:VOLts`` for ``CH<x>:SCAle``, ``HORizontal:SECdiv`` and
``HORizontal:MAIn:SECdiv`` for their ``SCAle``, ``HDR`` for ``HEADer``, each "the same as" the
other in the manual) and its display format, ``DISplay:FORMat YT`` (the records are volts
against time; ``XY``, one channel against another, is not modelled: -221)."""
from __future__ import annotations

from ..scpi.engine import Call, Word
from ..scpi.status import ScpiError
from ..scpi.tree import Mnemonic

ALIASES = {"CH<n>:VOLts": "CH<n>:SCAle", "HORizontal:SECdiv": "HORizontal:SCAle",
           "HORizontal:MAIn:SECdiv": "HORizontal:MAIn:SCAle", "HDR": "HEADer"}
"""{the manual's other name: the command it names}."""


def register(tree, scope) -> None:
    """Add the TDS2000's other names and display format to the tree of ``scope`` (a
    VirtualScope) when it is a tds2000; after the commands they name are registered."""
    if scope.personality.name != "tds2000":
        return
    for alias, name in ALIASES.items():
        command = tree.find(tuple(Mnemonic(spec).long for spec in name.split(":"))).command
        tree.add(alias, write=command.write, read=command.read, bare=command.bare)

    def display_format(c: Call):
        if c.word(("YT", "XY")) == "XY":
            raise ScpiError(-221, f"{c.header} {c.arg().text}: the XY display (CH1 against CH2) is not modelled; "
                                  f"the records are volts against time (YT)")

    tree.add("DISplay:FORMat", write=display_format, read=lambda c: Word("YT"))
