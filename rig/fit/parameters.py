"""What a fit may vary: numeric scene keys with bounds in units (``KEY=LO:HI``)."""
from __future__ import annotations

from dataclasses import dataclass

from rig.errors import RigError, invalid
from rig.experiment.scene import key_spec
from rig.model.laws import OWNER, PARAMETERS
from rig.units import check_digits, is_number, number, quantity

LAW_KEYS = {PARAMETERS[key].field: tuple(law.name for law in laws) for key, laws in OWNER.items()}
"""The keys that belong to some contact laws (rig.model.laws), with those laws' names: fitting
one selects the first of them (or the scene's law where it is one of them)."""
POSITIVE_LAW_KEYS = {field: laws for field, laws in LAW_KEYS.items() if PARAMETERS[field[len("chain."):]].switch}
"""Keys that switch a contact law on (their laws need them > 0)."""


@dataclass(frozen=True)
class FitParameter:
    """A scene key varied between lo and hi (in its SI unit ``unit``; "1": a pure number)."""

    key: str
    lo: float
    hi: float
    unit: str

    def override(self, value: float) -> str:
        """The --set text of this key at ``value`` (SI)."""
        return f"{self.key}={float(value)!r}"

    def shown(self, value: float) -> str:
        return f"{value:.6g}" if self.unit == "1" else f"{value:.6g} {self.unit}"


def parse_parameter(text: str) -> FitParameter:
    """``KEY=LO:HI``: a numeric scene key, each bound with the key's unit (a pure number for a
    dimensionless key), LO < HI. Raises RigError naming what is wrong."""
    if "=" not in text:
        raise invalid("--param", text, "needs bounds: KEY=LO:HI, e.g. chain.youngs_modulus=0.4 GPa:2 GPa")
    key, bounds = (s.strip() for s in text.split("=", 1))
    try:
        spec = key_spec(key)
    except RigError as exc:
        raise RigError(f"--param {exc}") from None
    if spec is float:
        unit = "1"
    elif isinstance(spec, str):
        unit = spec
    else:
        raise invalid("--param", key, "not a numeric scene key (a quantity or a number)")
    if bounds.count(":") != 1:
        raise invalid(f"--param {key}", bounds, "bounds LO:HI, e.g. 0.4 GPa:2 GPa")
    lo_text, hi_text = (s.strip() for s in bounds.split(":"))
    values = []
    for name, t in (("LO", lo_text), ("HI", hi_text)):
        field = f"--param {key} {name}"
        check_digits(t, field)
        if unit == "1":
            values.append(number(t, field, "a finite number (this key has no unit)"))
            continue
        if is_number(t):
            raise invalid(field, t, f"bounds need units, e.g. '{t} {unit}'")
        values.append(quantity(t, unit, field))
    lo, hi = values
    if not lo < hi:
        raise invalid(f"--param {key}", bounds, "needs LO < HI, the lower bound first")
    if key in POSITIVE_LAW_KEYS and lo <= 0:
        raise invalid(f"--param {key} LO", lo_text, f"> 0 (the {' and '.join(POSITIVE_LAW_KEYS[key])} law needs it; "
                                                   "leave the key out to fit without it)")
    law_parameter = PARAMETERS.get(key.split(".", 1)[1]) if key.startswith("chain.") else None
    if law_parameter is not None:  # both bounds inside what the contact law allows
        for value in (lo, hi):
            law_parameter.read(value)
    return FitParameter(key, lo, hi, unit)


def parse_parameters(texts) -> tuple:
    params = tuple(parse_parameter(t) for t in texts or ())
    if not params:
        raise RigError("--param: no parameter to fit; give at least one KEY=LO:HI")
    keys = [p.key for p in params]
    for k in keys:
        if keys.count(k) > 1:
            raise invalid("--param", k, "each key once")
    return params


def law_overrides(params, overrides=()) -> list:
    """The contact-law switch the fitted keys need (chain.contact_law=...): none where they
    belong to no law or ``overrides`` (--set texts) already name a law they all belong to;
    else the first law (rig.model.laws.LAWS' order) they all belong to."""
    owners = [LAW_KEYS[p.key] for p in params if p.key in LAW_KEYS]
    if not owners:
        return []
    common = [name for name in owners[0] if all(name in o for o in owners)]
    if not common:
        keys = ", ".join(p.key for p in params if p.key in LAW_KEYS)
        raise invalid("--param", keys, "keys of different contact laws; one law at a time: "
                                       + "; ".join(f"{k}: {' or '.join(v)}" for k, v in LAW_KEYS.items()))
    named = [item.partition("=")[2].strip().lower() for item in overrides
             if item.partition("=")[0].strip() == "chain.contact_law"]
    if named and named[-1] in common:
        return []
    return [f"chain.contact_law={common[0]}"]
