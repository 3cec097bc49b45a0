"""Hertz's law, and a power law of another exponent: the elastic part of every contact law.

    F = A delta^n  (delta > 0),  0 otherwise;  U = A delta^(n+1) / (n+1)

n = 3/2 is Hertz's (Johnson, *Contact Mechanics*, 1985; A = (4/3) E_eff sqrt(R_eff)); another n
describes a contact that departs from it (a polymer's modulus that depends on strain and
strain rate, rough surfaces), A_n matched to Hertz at reference_force
(rig.model.contact.power_law_constant). Conservative.
"""
from rig.model.laws.law import ELASTIC, HERTZ, ContactLaw, LawParameter, ViscousTerms

ELASTIC_PARAMETERS = (
    LawParameter("contact_exponent", "1", 1.0, 3.0, 1.5,
                 "exponent n of the elastic law A delta^n (1.5: Hertz)"),
    LawParameter("reference_force", "N", 0.0, float("inf"), 1.0,
                 "force (N) at which a power law A_n delta^n meets the Hertz contact of the same parts",
                 lo_open=True),
)
"""Every law's elastic parameters (scene keys of [chain])."""


def viscous_terms(values: dict) -> ViscousTerms:
    """No viscous term: an elastic contact."""
    return ELASTIC


LAW = ContactLaw(
    "hertz",
    "elastic F = A delta^n: Hertz's law at n = 3/2 (the default), a power law otherwise (conservative)",
    (), viscous_terms, HERTZ)
