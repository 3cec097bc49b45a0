"""The program message parser (IEEE 488.2 7, SCPI 1999 6).

A message is program message units separated by ``;`` (outside quoted strings and
blocks). A unit is a header, then, after white space, arguments separated by ``,``. A
header is a common command (``*IDN?``) or mnemonics joined by ``:`` with an optional
leading ``:`` (from the root) and a trailing ``?`` (a query). Arguments are numbers (with a
suffix), character data (``RIBinary``), strings ("..." or '...', the quote doubled inside)
and blocks (``#<n><len><bytes>``). The bytes are read as Latin-1, so a block's bytes pass
unchanged."""
from __future__ import annotations

import re
from dataclasses import dataclass

from .blocks import block_end
from .numbers import DECIMAL
from .status import ScpiError

COMMON = re.compile(r"\*[A-Za-z]{2,8}\??")
MNEMONIC = re.compile(r"[A-Za-z][A-Za-z0-9_]*")
WORD = re.compile(r"[A-Za-z][A-Za-z0-9_]*")
NUMBER_WITH_SUFFIX = re.compile(DECIMAL.pattern + r"\s*[A-Za-z/%.^0-9*-]*|#[HhQqBb][0-9A-Fa-f]+")


@dataclass(frozen=True)
class Argument:
    """One argument: kind "number" | "word" | "string" | "block"; text as sent (a
    string's text unquoted, a block's payload as Latin-1)."""

    kind: str
    text: str


@dataclass(frozen=True)
class Unit:
    """One program message unit, its mnemonics in upper case."""

    header: str
    mnemonics: tuple
    common: bool
    query: bool
    absolute: bool
    args: tuple


def split_units(message: bytes) -> list:
    """The units of a message, as text (quotes and blocks respected, so a ``;`` inside one
    does not split). An unterminated string is -150."""
    text = message.decode("latin-1")
    units, start, i, n = [], 0, 0, len(text)
    while i < n:
        c = text[i]
        if c in "\"'":
            close = text.find(c, i + 1)
            while close != -1 and text[close + 1:close + 2] == c:
                close = text.find(c, close + 2)
            if close == -1:
                raise ScpiError(-150, "unterminated string")
            i = close + 1
        elif c == "#" and text[i + 1:i + 2].isdigit():
            end = block_end(message, i)
            if end is None:
                raise ScpiError(-160, "the block's length disagrees with the bytes sent")
            i = end
        elif c == ";":
            units.append(text[start:i])
            start = i = i + 1
        else:
            i += 1
    units.append(text[start:])
    return [u for u in units if u.strip(" \t\r\n")]


def parse_unit(text: str) -> Unit:
    """One unit's header and arguments; ScpiError for a malformed one."""
    body = text.strip(" \t\r\n")
    head, rest = (re.split(r"\s+", body, maxsplit=1) + [""])[:2]
    if not head.isascii() or not head.isprintable():
        raise ScpiError(-101, f"in header {head[:40]!r}")
    query = head.endswith("?")
    mnemonics: tuple[str, ...]
    if COMMON.fullmatch(head):
        mnemonics, common, absolute = (head.rstrip("?").upper(),), True, True
    else:
        absolute = head.startswith(":")
        parts = head[1 if absolute else 0:].rstrip("?").split(":") if head not in (":", "") else [""]
        if head.count("?") > 1 or not all(MNEMONIC.fullmatch(p) for p in parts):
            raise ScpiError(-102, f"header {head[:40]!r}")
        mnemonics, common = tuple(p.upper() for p in parts), False
    return Unit(head, mnemonics, common, query, absolute, parse_arguments(rest))


def parse_arguments(text: str) -> tuple:
    """The comma-separated arguments of a unit."""
    args: list[Argument] = []
    i, n = 0, len(text)
    while True:
        while i < n and text[i] in " \t\r\n":
            i += 1
        if i >= n:
            if args:
                raise ScpiError(-109, "an argument is missing after ','")
            return ()
        arg, i = _argument(text, i)
        args.append(arg)
        while i < n and text[i] in " \t\r\n":
            i += 1
        if i >= n:
            return tuple(args)
        if text[i] != ",":
            raise ScpiError(-103, f"expected ',' at {text[i:i + 20]!r}")
        i += 1


def _argument(text: str, i: int) -> tuple:
    c = text[i]
    if c in "\"'":
        j, parts = i + 1, []
        while True:
            close = text.find(c, j)
            if close == -1:
                raise ScpiError(-150, "unterminated string")
            parts.append(text[j:close])
            if text[close + 1:close + 2] != c:
                return Argument("string", c.join(parts)), close + 1
            j = close + 2
    if c == "#" and text[i + 1:i + 2].isdigit():
        raw = text.encode("latin-1")
        end = block_end(raw, i)
        if end is None:
            raise ScpiError(-160, "the block's length disagrees with the bytes sent")
        n = int(text[i + 1])
        return Argument("block", text[i + 2 + n if n else i + 2:end]), end
    m = NUMBER_WITH_SUFFIX.match(text, i)
    if m and (m.end() == len(text) or text[m.end()] in " \t\r\n,"):
        return Argument("number", m.group()), m.end()
    m = WORD.match(text, i)
    if m and (m.end() == len(text) or text[m.end()] in " \t\r\n,"):
        return Argument("word", m.group()), m.end()
    raise ScpiError(-141, f"argument {text[i:i + 40]!r}")
