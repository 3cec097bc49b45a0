"""The command tree: handlers registered under their long mnemonics, matched by either form.

A pattern is mnemonics joined by ``:``, each written as the programmer manuals print it:
the short form in upper case, the rest of the long form in lower case (``DATa:ENCdg``
matches DAT:ENC, DATA:ENCDG, data:encdg). A mnemonic ending in ``<n>`` takes a numeric
suffix (``CH<n>``: CH1 .. CH4; a missing suffix is 1, SCPI 1999 6.2.5). Common commands
are registered as ``*IDN`` and so on. A tree made with ``truncation=True`` also takes any
spelling between the two forms (DATA:SOUR for DATa:SOUrce), as Tektronix scopes do and
their own example scripts rely on; an exact form is preferred where both could match."""
from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass, field

SUFFIX = re.compile(r"([A-Z_]*[A-Z_])(\d*)$")


@dataclass(frozen=True)
class Mnemonic:
    """One node of a pattern: its long and short forms, and whether it takes a suffix."""

    spec: str

    @property
    def numbered(self) -> bool:
        return self.spec.endswith("<n>")

    @property
    def long(self) -> str:
        return self.spec.removesuffix("<n>").upper()

    @property
    def short(self) -> str:
        return "".join(c for c in self.spec.removesuffix("<n>") if not c.islower())

    def match(self, token: str, truncated: bool = False):
        """The suffix (int, or None for an unnumbered node) when token names this node,
        else False; ``truncated``: a spelling between the short and the long form names it."""
        if not self.numbered:
            return None if self.spelled(token, truncated) else False
        m = SUFFIX.match(token)
        if not m or not self.spelled(m.group(1), truncated):
            return False
        return int(m.group(2)) if m.group(2) else 1

    def spelled(self, word: str, truncated: bool) -> bool:
        """Whether ``word`` is the short or the long form (or, truncated, one between)."""
        return word in (self.long, self.short) or (
            truncated and word.startswith(self.short) and self.long.startswith(word))

    def form(self, verbose: bool, suffix) -> str:
        """The node in a reply header: long or short, with its suffix."""
        return (self.long if verbose else self.short) + ("" if suffix is None else str(suffix))


@dataclass(frozen=True)
class Command:
    """What a pattern does: ``write(call)`` for the command form, ``read(call)`` for the
    query; ``bare``: its reply carries no header (IEEE 488.2 common queries)."""

    write: Callable | None = None
    read: Callable | None = None
    bare: bool = False


@dataclass
class Node:
    mnemonic: Mnemonic
    command: Command | None = None
    children: list = field(default_factory=list)


@dataclass(frozen=True)
class Found:
    """A header resolved: the command, the matched nodes and their suffixes."""

    command: Command
    nodes: tuple
    suffixes: tuple

    def header(self, verbose: bool) -> str:
        """The reply header, ``:DATA:ENCDG`` (verbose) or ``:DAT:ENC``."""
        return ":" + ":".join(m.form(verbose, s) for m, s in zip(self.nodes, self.suffixes))


class CommandTree:
    """The command tree of an instrument."""

    def __init__(self, *, truncation: bool = False) -> None:
        self.root = Node(Mnemonic(""))
        self.truncation = truncation

    def add(self, pattern: str, *, write=None, read=None, bare=False) -> None:
        """Register a pattern's handlers (ValueError for a pattern given twice)."""
        node = self.root
        for spec in pattern.split(":"):
            child = next((c for c in node.children if c.mnemonic.spec.upper() == spec.upper()), None)
            if child is None:
                child = Node(Mnemonic(spec))
                node.children.append(child)
            node = child
        if node.command is not None:
            raise ValueError(f"{pattern} registered twice")
        node.command = Command(write, read, bare)

    def find(self, tokens) -> Found | None:
        """The command a header's mnemonics (upper case) name, or None."""
        node, nodes, suffixes = self.root, [], []
        for token in tokens:
            node, suffix = self._child(node, token)
            if node is None:
                return None
            nodes.append(node.mnemonic)
            suffixes.append(suffix)
        return Found(node.command, tuple(nodes), tuple(suffixes)) if node.command else None

    def _child(self, node: Node, token: str) -> tuple:
        """(the child of ``node`` that ``token`` names, its suffix), or (None, False);
        an exact form first, then (``truncation``) a spelling between the forms."""
        for truncated in (False, True) if self.truncation else (False,):
            for child in node.children:
                suffix = child.mnemonic.match(token, truncated)
                if suffix is not False:
                    return child, suffix
        return None, False
