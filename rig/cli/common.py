"""Helpers shared by the commands."""
from __future__ import annotations

import argparse
import math
import sys

MAX_SEED = 2**63 - 1  # seeds are stored as signed 64-bit integers


class OneLineParser(argparse.ArgumentParser):
    """argparse with the project's error policy: a mistake is one line, exit 2."""

    def error(self, message):
        print(f"{self.prog}: error: {message}", file=sys.stderr)
        sys.exit(2)


def seed_arg(text: str) -> int:
    """A seed: a whole number from 0 to 2^63 - 1."""
    try:
        seed = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r}: a whole number from 0 to {MAX_SEED}") from None
    if not 0 <= seed <= MAX_SEED:
        raise argparse.ArgumentTypeError(f"{text!r}: a whole number from 0 to {MAX_SEED}")
    return seed


def quantity_arg(text: str, unit: str, field: str) -> float:
    """A command-line quantity: a plain number is taken in ``unit``; else text with a unit."""
    from rig.units import quantity

    try:
        return float(text)
    except ValueError:
        return quantity(text, unit, field)


def quantity_type(unit: str, field: str, lo: float | None = None, lo_closed: bool = False, hi: float | None = None):
    """An argparse type for a quantity in ``unit`` (a plain number is taken in ``unit``);
    where ``lo`` or ``hi`` is given, a finite one above ``lo`` (or at it, with lo_closed) and
    at most ``hi``. A mistake is reported as the field, the value and what is allowed."""
    def parse(text: str) -> float:
        from rig.errors import RigError

        try:
            x = quantity_arg(text, unit, field)
        except RigError as exc:
            raise argparse.ArgumentTypeError(str(exc).removeprefix(f"{field} = ")) from None
        if lo is None and hi is None:
            return x  # the command checks the value itself
        low = lo is not None and (x < lo if lo_closed else x <= lo)
        if not math.isfinite(x) or low or (hi is not None and x > hi):
            rng = " ".join(filter(None, [f"{lo:g} {'<=' if lo_closed else '<'}" if lo is not None else "",
                                         "value", f"<= {hi:g}" if hi is not None else ""]))
            raise argparse.ArgumentTypeError(f"{text!r}: allowed a finite {rng}{' (' + unit + ')' if unit else ''}")
        return x

    parse.__name__ = f"quantity in {unit}" if unit else "number"
    return parse


def count_type(field: str, lo: int = 1):
    """An argparse type for a whole number >= lo."""
    def parse(text: str) -> int:
        try:
            n = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r}: allowed a whole number >= {lo}") from None
        if n < lo:
            raise argparse.ArgumentTypeError(f"{text!r}: allowed a whole number >= {lo}")
        return n

    parse.__name__ = field
    return parse
