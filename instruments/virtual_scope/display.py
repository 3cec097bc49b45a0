"""The display group of the model's programmer manual (manual.py): the emulated scope has
no screen, so what a program sets there changes no record; each setting is taken as the
manual's syntax gives it (one of its words, a number, a string) and read back as set. Until
set, a query answers the first of the manual's words, 0 (a number, or a switch: switches
answer 1 or 0), or an empty string. A number is answered as the syntax gives it: an integer
(NR1) where it says <NR1> alone, else in the model's NR3; a word of the manual that is a
number (the TDS2000's ``DISplay:PERSistence {1|2|5|INF|OFF}``) is taken as a number. Commands the
emulation models itself (DISplay:WAVEform, DISplay:GLObal:CH<x>:STATE, ...) keep their own
handlers."""
from __future__ import annotations

import re

from ..scpi.engine import Call, Word
from ..scpi.status import ScpiError
from .manual import MODELS, ManualCommand, manual

NUMBER_ARGS = re.compile(r"<NR[1-3f]>", re.IGNORECASE)
REAL_ARGS = re.compile(r"<NR[23f]>", re.IGNORECASE)
NUMERIC_WORD = re.compile(r"\d+(\.\d+)?")
BOOLEAN = {"ON", "OFF", "1", "0"}  # a switch: answered 1 or 0


def number_form(command: ManualCommand, nr3):
    """How the setting's numbers are answered: NR1 where the syntax gives <NR1> alone, else ``nr3``."""
    return (lambda x: str(round(x))) if "<NR1>" in command.args.upper() and not REAL_ARGS.search(command.args) else nr3


def numeric_word(c: Call, words) -> str | None:
    """The word of ``words`` that the number argument names (``2.0`` names ``2``), or None."""
    x = c.number()
    return next((w for w in words if NUMERIC_WORD.fullmatch(w) and float(w) == x), None)


def default(command: ManualCommand, number) -> str:
    """What a query answers before a client sets the setting."""
    if command.words and {w.upper() for w in command.words} <= BOOLEAN:
        return "0"
    if command.words:
        return Word(command.words[0])
    if NUMBER_ARGS.search(command.args):
        return number(0.0)
    return '""'


def register(tree, scope) -> None:
    """Add the display settings of ``scope``'s manual that the tree does not hold yet."""
    model = scope.personality.name
    if model not in MODELS:
        return
    kept: dict = {}  # (header, suffixes) -> the answer

    def handlers(command: ManualCommand):
        plain_words = command.words and all("<" not in w for w in command.words)
        takes_number = NUMBER_ARGS.search(command.args) is not None
        boolean = {w.upper() for w in command.words} <= BOOLEAN
        number = number_form(command, scope.personality.number)

        def write(c: Call):
            if command.words and boolean:
                value = "1" if c.boolean() else "0"
            elif takes_number and c.arg().kind == "number":
                value = number(c.number())
            elif plain_words:
                named = numeric_word(c, command.words) if c.arg().kind == "number" else None
                value = named or Word(c.word(command.words))
            elif takes_number:
                value = number(c.number())
            else:
                value = ",".join(a.text for a in c.args)
                c.taken[0] = len(c.args)
                if not value:
                    raise ScpiError(-109, f"{c.header} needs an argument: {command.args}")
            kept[command.header, c.suffixes] = value

        def read(c: Call):
            return kept.get((command.header, c.suffixes), default(command, number))

        return (write if command.write else None), (read if command.query else None)

    for command in manual(model):
        if command.group != "display" or "{" in command.header:
            continue
        tokens = tuple(part.upper() for part in command.concrete.split(":"))
        if tree.find(tokens) is not None:
            continue
        write, read = handlers(command)
        tree.add(command.header.replace("<x>", "<n>"), write=write, read=read)
