"""Executing one program message: path inheritance, events, reply forms.

Path inheritance (IEEE 488.2 A.1.1, SCPI 1999 6.2.4): after a unit, the following unit
that does not start with ``:`` is looked up below the node that held the previous unit's
last mnemonic; a common command (``*XXX``) leaves that path alone; every message starts at
the root. A relative header that names nothing there is tried from the root, as Tektronix
scopes take ``CH1:SCALE 0.1;CH2:SCALE 0.1``. Replies of the queries of one message are joined by ``;`` on one line.
Reply forms as the Tektronix programmer manuals give them (HEADer, VERBose): with HEADer ON
a reply starts with the query's path, ``:DATA:ENCDG RIBINARY``, in long forms with VERBose
ON and short ones (``:DAT:ENC RIB``) with it OFF; an enumerated value (``Word``) is given in
its long form with VERBose ON, its short form otherwise. A query that fails answers nothing
(IEEE 488.2 6.4.5) and leaves its event in the queue. A handler that fails other than with
an event (a bug) leaves -200 "internal fault" and the message goes on."""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

from .numbers import number
from .parser import Argument, parse_unit, split_units
from .status import ScpiError, StatusModel
from .tree import CommandTree, Mnemonic

INTERNAL = "internal fault"  # the words of the event a handler's own fault (a bug) leaves
LATER = object()
"""What a query's handler returns when its answers come later, one at a time, from its
instrument (CURVEStream?): the message answers nothing for it now."""


class Word(str):
    """An enumerated value as the manual prints it (``RIBinary``), answered long or short."""

    def form(self, verbose: bool) -> str:
        m = Mnemonic(self)
        return m.long if verbose else m.short


class IllegalWord(ScpiError):
    """-224 "Illegal parameter value": a word the handler does not take (``word``: as sent)."""

    def __init__(self, detail: str, word: str) -> None:
        super().__init__(-224, detail)
        self.word = word


@dataclass(frozen=True)
class Fields:
    """A group query's answer (``WFMPre?``): (mnemonic as printed, value) pairs, answered
    ``:WFMPRE:BYT_NR 1;BIT_NR 8;...`` with HEADer ON and ``1;8;...`` with it OFF."""

    pairs: tuple


@dataclass
class ReplyForm:
    """HEADer and VERBose, the instrument's reply forms."""

    header: bool = True
    verbose: bool = True


@dataclass(frozen=True)
class Call:
    """What a handler is given: the arguments, the header's numeric suffixes, the unit's
    header as sent (for events) and ``context``, the instrument's object for its session."""

    args: tuple
    suffixes: tuple
    header: str
    context: object = None
    taken: list = field(default_factory=lambda: [0], compare=False)  # how many arguments the handler read

    @property
    def suffix(self) -> int:
        """The last numeric suffix in the header (CH<n>: n)."""
        return next((s for s in reversed(self.suffixes) if s is not None), 1)

    def arg(self, i: int = 0) -> Argument:
        if i >= len(self.args):
            raise ScpiError(-109, f"{self.header} needs {i + 1} argument(s)")
        self.taken[0] = max(self.taken[0], i + 1)
        return self.args[i]

    def unread(self) -> tuple:
        """The arguments the handler did not read (a setting given one value too many)."""
        return self.args[self.taken[0]:]

    def only(self, count: int) -> None:
        if len(self.args) > count:
            raise ScpiError(-108, f"{self.header} takes {count} argument(s)")

    def number(self, unit: str = "", i: int = 0) -> float:
        """Argument i as a number in SI units (``50mV`` -> 0.05 for unit "V")."""
        a = self.arg(i)
        if a.kind != "number":
            raise ScpiError(-104, f"{self.header} {a.text[:40]!r}: expected a number"
                                  f"{' in ' + unit if unit else ''}")
        return number(a.text, unit)

    def word(self, choices, i: int = 0) -> str:
        """Argument i as one of ``choices`` (as printed, ``RIBinary``), given in its long or
        short form; returns the choice as printed."""
        a = self.arg(i)
        text = a.text.upper()
        for c in choices:
            m = Mnemonic(c)
            if a.kind == "word" and text in (m.long, m.short):
                return c
        raise IllegalWord(f"{self.header} {a.text[:40]!r}: allowed {', '.join(choices)}", a.text)

    def boolean(self, i: int = 0) -> bool:
        """Argument i as ON/OFF or a number (non-zero is ON, IEEE 488.2 7.7.2 rounded)."""
        a = self.arg(i)
        if a.kind == "number":
            return round(number(a.text)) != 0
        return self.word(("ON", "OFF"), i) == "ON"


@dataclass
class Engine:
    """Runs messages against a command tree, with the instrument's status model and reply
    forms. Not thread-safe: its owner runs one message at a time."""

    tree: CommandTree
    status: StatusModel = field(default_factory=StatusModel)
    form: ReplyForm = field(default_factory=ReplyForm)
    manual_word: Callable[[str, str], bool] | None = None
    """(the header found, long form, e.g. ``:CH1:COUPLING``; a word as sent) -> whether the
    instrument's manual lists it: such a word a handler does not take is a setting not
    modelled (-221 "Settings conflict"), not an illegal value (-224)."""

    def execute(self, message: bytes, context=None) -> bytes:
        """Run every unit of a message; the replies of its queries, joined by ``;`` and
        ending in ``\\n`` (b"" when there were none)."""
        try:
            units = split_units(message)
        except ScpiError as e:
            self.status.post(e.code, e.detail)
            return b""
        path, replies = (), []
        for text in units:
            try:
                unit = parse_unit(text)
            except ScpiError as e:
                self.status.post(e.code, e.detail)
                continue
            tokens = unit.mnemonics if unit.absolute or unit.common else path + unit.mnemonics
            found = self.tree.find(tokens)
            if found is None and tokens is not unit.mnemonics:  # lenient, as Tek parsers are
                tokens, found = unit.mnemonics, self.tree.find(unit.mnemonics)
            if found is not None and not unit.common:
                path = tokens[:-1]
            handler = None if found is None else (found.command.read if unit.query else found.command.write)
            if found is None or handler is None:
                self.status.post(-113, unit.header[:60])
                continue
            call = Call(unit.args, found.suffixes, unit.header, context)
            try:
                value = handler(call)
            except ScpiError as e:
                if isinstance(e, IllegalWord) and self.manual_word is not None \
                        and self.manual_word(found.header(True), e.word):
                    e = ScpiError(-221, f"{unit.header[:60]} {e.word[:40]}: in the manual, not modelled here")
                self.status.post(e.code, f"{e.detail}" if e.detail else unit.header[:60])
                continue
            except Exception as e:  # noqa: BLE001 - a handler's fault must not drop the client
                self.status.post(-200, f"{INTERNAL} in {unit.header[:60]}: {type(e).__name__}: {e}")
                continue
            extra = call.unread()
            if extra and not unit.query:  # IEEE 488.2: -108 Parameter not allowed (the value read was set)
                self.status.post(-108, f"{unit.header[:60]} takes {call.taken[0]} argument(s); "
                                       f"{', '.join(a.text[:20] for a in extra)} not allowed")
            if unit.query and value is not LATER:
                replies.append(self.reply(value, found))
        return b";".join(replies) + b"\n" if replies else b""

    def reply(self, value, found) -> bytes:
        """One query's reply in the current forms."""
        verbose, header = self.form.verbose, self.form.header and not found.command.bare
        if isinstance(value, Fields):
            items = [(Mnemonic(k).form(verbose, None), self.text(v)) for k, v in value.pairs]
            if not header:
                return b";".join(v for _, v in items)
            first = f"{found.header(verbose)}:{items[0][0]} ".encode() + items[0][1]
            return b";".join([first] + [k.encode() + b" " + v for k, v in items[1:]])
        body = self.text(value)
        return (found.header(verbose).encode() + b" " + body) if header else body

    def text(self, value) -> bytes:
        """A value's bytes: a Word in the current form, bytes as they are, else str()."""
        if isinstance(value, bytes):
            return value
        if isinstance(value, Word):
            return value.form(self.form.verbose).encode()
        return str(value).encode("latin-1", "replace")
