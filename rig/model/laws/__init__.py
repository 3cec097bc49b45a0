"""The contact laws between neighbours, one module each (its name, equation, reference,
parameters and the viscous terms it hands the kernels), and their registry.

A new law is a module here with a ``LAW`` (rig.model.laws.law.ContactLaw) added to LAWS;
the scene keys of [chain] (rig.experiment.scene.SCHEMA), the chain's checks
(rig.model.chain.Chain), the assembly and ``rig fit``'s keys (rig.fit.parameters) read
their parameters from here.
"""
from __future__ import annotations

from rig.errors import invalid, lookup
from rig.model.laws import dashpot, hertz, kuwabara_kono, powerlaw_dashpot, thornton
from rig.model.laws.law import HERTZ, KUWABARA_KONO, PLASTIC, POWER, ContactLaw, LawParameter, ViscousTerms

MODULES = (hertz, kuwabara_kono, dashpot, powerlaw_dashpot, thornton)
"""The laws' modules (their kernel functions compiled by rig.solver.kernels)."""
LAWS = tuple(module.LAW for module in MODULES)

CONTACT_LAWS: dict[str, ContactLaw] = {law.name: law for law in LAWS}

PARAMETERS: dict[str, LawParameter] = {p.key: p for p in tuple(
    q for law in LAWS for q in law.parameters) + hertz.ELASTIC_PARAMETERS}
"""Every law's parameters by scene key (chain.<key>): each law's own, then the elastic ones."""

ALTERNATIVE_SWITCHES = {"yield_force": ("yield_pressure",)}
"""A law's switch that another parameter may turn on instead (not both): Thornton's yield
is a force (chain.yield_force) or a pressure (chain.yield_pressure)."""
OWNER: dict[str, tuple] = {p.key: tuple(law for law in LAWS if p in law.parameters)
                           for p in (q for law in LAWS for q in law.parameters)}
"""The laws each law-specific parameter belongs to (a dashpot's coefficient: the dashpot's and
the elastic-plastic law's)."""

__all__ = ["CONTACT_LAWS", "ContactLaw", "HERTZ", "KUWABARA_KONO", "LAWS", "LawParameter", "MODULES", "OWNER",
           "PARAMETERS",
           "PLASTIC", "POWER", "ViscousTerms", "contact_law", "law_values"]


def contact_law(name) -> ContactLaw:
    """Look a contact law up by name (the scene key chain.contact_law)."""
    return lookup(CONTACT_LAWS, name, "chain.contact_law", ContactLaw)


def law_values(law: ContactLaw, given: dict) -> dict:
    """Every parameter's SI value ({key: float}) for a chain of ``law``: ``given`` read and
    checked (PARAMETERS), the others at their defaults. Refused, naming the key: an unknown
    key, a value out of bounds, the law's switch left at 0, another law's parameter set."""
    for key in given:
        if key not in PARAMETERS:
            raise invalid("chain", key, f"not a contact parameter; known: {', '.join(PARAMETERS)}")
    values = {key: (p.read(given[key]) if key in given else p.default) for key, p in PARAMETERS.items()}
    for key, owners in OWNER.items():
        p = PARAMETERS[key]
        if law not in owners and values[key] != p.default:
            names = " or ".join(repr(o.name) for o in owners)
            raise invalid(p.field, values[key], f"belongs to contact law {names}, not {law.name!r}; "
                                                f"leave it {p.default:g}")
        if p.switch and values[key] == 0 and p.key == law.parameter and not any(
                values[k] > 0 for k in ALTERNATIVE_SWITCHES.get(key, ())):
            also = "".join(f" (or {PARAMETERS[k].field} > 0)" for k in ALTERNATIVE_SWITCHES.get(key, ()))
            raise invalid(p.field, values[key], f"contact law {law.name!r} needs it > 0{also}")
    for key, others in ALTERNATIVE_SWITCHES.items():
        for other in others:
            if values[key] > 0 and values[other] > 0:
                raise invalid(PARAMETERS[other].field, values[other],
                              f"give one of {PARAMETERS[other].field} or {PARAMETERS[key].field} "
                              f"(here {values[key]:g} {PARAMETERS[key].unit}), not both")
    return values
