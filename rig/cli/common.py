"""Helpers shared by the commands."""
from __future__ import annotations


def quantity_arg(text: str, unit: str, field: str) -> float:
    """A command-line quantity: a plain number is taken in ``unit``; else text with a unit."""
    from rig.units import quantity

    try:
        return float(text)
    except ValueError:
        return quantity(text, unit, field)
