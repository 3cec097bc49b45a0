"""Helpers shared by the commands."""
from __future__ import annotations

import argparse
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


def quantity_type(unit: str, field: str):
    """An argparse type for a quantity in ``unit`` (a plain number is taken in ``unit``);
    a mistake is reported as the field, the value and what is allowed."""
    def parse(text: str) -> float:
        from rig.errors import RigError

        try:
            return quantity_arg(text, unit, field)
        except RigError as exc:
            raise argparse.ArgumentTypeError(str(exc).removeprefix(f"{field} = ")) from None

    parse.__name__ = f"quantity in {unit}"
    return parse
