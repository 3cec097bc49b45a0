"""A linear dashpot beside the elastic contact:

    F = max(A delta^n + mu d(delta)/dt, 0)    while in contact

damping proportional to the relative velocity of the two beads (Herbold & Nesterenko,
Phys. Rev. E 75, 021304 (2007); Rosas, Romero, Nesterenko & Lindenberg, Phys. Rev. Lett. 98,
164301 (2007)); mu (kg/s) is chain.contact_damping.
"""
from rig.model.laws.law import KUWABARA_KONO, ContactLaw, LawParameter, ViscousTerms

CONTACT_DAMPING = LawParameter("contact_damping", "kg/s", 0.0, float("inf"), 0.0,
                               "dashpot coefficient mu (kg/s) of each contact", switch=True)


def viscous_terms(values: dict) -> ViscousTerms:
    """A linear dashpot of mu kg/s (the chain's values, {key: SI value})."""
    return ViscousTerms(dashpot=values["contact_damping"])


LAW = ContactLaw(
    "dashpot",
    "elastic A delta^n plus a dashpot mu d(delta)/dt while in contact, never attractive: damping "
    "proportional to the relative velocity of the two beads (Herbold & Nesterenko, Phys. Rev. E 75, "
    "021304 (2007); Rosas, Romero, Nesterenko & Lindenberg, Phys. Rev. Lett. 98, 164301 (2007)); mu "
    "(kg/s) is chain.contact_damping",
    (CONTACT_DAMPING,), viscous_terms, KUWABARA_KONO)
