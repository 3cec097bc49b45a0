"""What a contact law is: its parameters (scene keys of [chain], with units, bounds,
defaults and docs) and the viscous terms it hands the kernels.

Every law has the elastic part A delta^n (rig.model.laws.hertz: n = chain.contact_exponent,
3/2 by default); a dissipative law adds a viscous force while the contact is closed, which
the kernels take as three numbers per contact (``ViscousTerms``): a Kuwabara-Kono damping
time tau (s) and a dashpot gamma |d'|^alpha sgn(d') (gamma in N (s/m)^alpha; alpha = 1: a
linear dashpot of gamma kg/s).
"""
from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

from rig.errors import invalid
from rig.units import number, quantity

# The kernels' code of a chain's contact forces (rig/solver/kernels/forces.py), chosen from
# its contacts (rig/solver/problem.py), not named by users: HERTZ, every contact elastic
# Hertz; KUWABARA_KONO, every contact Hertz with viscous terms (Kuwabara-Kono's and/or a
# dashpot), vectorised; POWER, any exponent per contact (scalar: a pow per contact);
# PLASTIC, contacts that yield and remember it (rig.model.laws.thornton; scalar, stateful).
HERTZ = 0
KUWABARA_KONO = 1
POWER = 2
PLASTIC = 3


@dataclass(frozen=True)
class LawParameter:
    """A contact law's parameter: the scene key chain.<key>, read in ``unit`` (an SI unit
    rig.units reads; "1": a plain number, in SI), allowed in [lo, hi] (lo itself excluded
    where ``lo_open``), ``default`` when the scene leaves it out. ``switch``: the law needs it
    > 0 (the key that turns the law on when a fit varies it)."""

    key: str
    unit: str
    lo: float
    hi: float
    default: float
    doc: str
    lo_open: bool = False
    switch: bool = False

    @property
    def field(self) -> str:
        return f"chain.{self.key}"

    @property
    def scene_spec(self):
        """Its entry in the scene SCHEMA: the unit, or float for a plain number."""
        return float if self.unit == "1" else self.unit

    @property
    def allowed(self) -> str:
        unit = "" if self.unit == "1" else f" {self.unit}"
        lo = "(" if self.lo_open else "["
        if math.isinf(self.hi):
            return f"must be {'>' if self.lo_open else '>='} {self.lo:g}{unit}"
        return f"a number in {lo}{self.lo:g}, {self.hi:g}]{unit} (default {self.default:g})"

    def read(self, value) -> float:
        """The value in SI (a number, or a quantity in ``unit``), checked against its bounds;
        RigError naming chain.<key>, the value and what is allowed otherwise."""
        if self.unit == "1":
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise invalid(self.field, value, self.allowed)
            x = number(value, self.field, self.allowed)
        else:
            x = quantity(value, self.unit, self.field, bare_ok=True)
        inside = (x > self.lo if self.lo_open else x >= self.lo) and x <= self.hi
        if not inside:
            raise invalid(self.field, value, self.allowed)
        return x


@dataclass(frozen=True)
class ViscousTerms:
    """What a law hands the kernels for each of its contacts: Kuwabara-Kono's damping time
    tau (s), a dashpot's coefficient gamma (N (s/m)^alpha; kg/s at alpha = 1) and exponent
    alpha (1: linear). The viscous force of a contact at overlap d > 0 closing at rate d'
    is A tau d^(n-1) d' + gamma |d'|^alpha sgn(d'), the whole contact force never attractive."""

    damping_time: float = 0.0
    dashpot: float = 0.0
    dashpot_exponent: float = 1.0


ELASTIC = ViscousTerms()


@dataclass(frozen=True)
class ContactLaw:
    """A contact law between neighbours: what ``chain.contact_law`` names. ``parameters``:
    its own (the elastic part's, every law's, are rig.model.laws.hertz.ELASTIC_PARAMETERS);
    ``viscous``: its ViscousTerms from the chain's parameter values ({key: SI value});
    ``code``: the kernels' code of its path with Hertz's exponent; ``yielding``: its
    rig.model.laws.thornton.YieldTerms from the values (None: a law whose contacts never
    yield)."""

    name: str
    description: str
    parameters: tuple
    viscous: Callable[[dict], ViscousTerms]
    code: int
    yielding: Callable | None = None

    @property
    def dissipative(self) -> bool:
        return self.code != HERTZ

    @property
    def parameter(self) -> str | None:
        """The parameter that turns the law on (it needs it > 0); None for an elastic law."""
        return next((p.key for p in self.parameters if p.switch), None)
