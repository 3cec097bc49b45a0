"""A power-law dashpot beside the elastic contact:

    F = max(A delta^n + gamma |d(delta)/dt|^alpha sgn(d(delta)/dt), 0)    while in contact

(Carretero-Gonzalez, Khatri, Porter, Kevrekidis & Daraio, Phys. Rev. Lett. 102, 024102
(2009), who fitted alpha to granular chains; alpha = 1 is the linear dashpot of
rig.model.laws.dashpot). gamma (N (s/m)^alpha) is chain.dashpot_gamma, a plain number in SI
since its unit depends on alpha; alpha (dimensionless) is chain.dashpot_exponent.
"""
from rig.model.laws.law import KUWABARA_KONO, ContactLaw, LawParameter, ViscousTerms

GAMMA = LawParameter("dashpot_gamma", "1", 0.0, float("inf"), 0.0,
                     "power-law dashpot coefficient gamma, N (s/m)^alpha (SI, a plain number)", switch=True)
ALPHA = LawParameter("dashpot_exponent", "1", 0.1, 3.0, 1.0,
                     "power-law dashpot exponent alpha (dimensionless; 1: a linear dashpot)")


def viscous_terms(values: dict) -> ViscousTerms:
    """A dashpot gamma |d'|^alpha sgn d' (the chain's values, {key: SI value})."""
    return ViscousTerms(dashpot=values["dashpot_gamma"], dashpot_exponent=values["dashpot_exponent"])


LAW = ContactLaw(
    "powerlaw-dashpot",
    "elastic A delta^n plus a power-law dashpot gamma |d(delta)/dt|^alpha sgn(d(delta)/dt) while in "
    "contact, never attractive (Carretero-Gonzalez, Khatri, Porter, Kevrekidis & Daraio, Phys. Rev. Lett. "
    "102, 024102 (2009)); gamma (N (s/m)^alpha, SI) is chain.dashpot_gamma, alpha chain.dashpot_exponent "
    "(1: the linear dashpot)",
    (GAMMA, ALPHA), viscous_terms, KUWABARA_KONO)
