"""Kuwabara and Kono's viscoelastic Hertz contact:

    F = max(A delta^(n-1) (delta + tau_d d(delta)/dt), 0)    while in contact

(Kuwabara & Kono, Jpn. J. Appl. Phys. 26, 1230 (1987); Brilliantov et al., Phys. Rev. E 53,
5382 (1996)); tau_d (s) is the material's damping time, chain.damping_time.
"""
from rig.model.laws.law import KUWABARA_KONO, ContactLaw, LawParameter, ViscousTerms

DAMPING_TIME = LawParameter("damping_time", "s", 0.0, float("inf"), 0.0,
                            "Kuwabara-Kono damping time tau_d (s) of the contacts' material", switch=True)


def viscous_terms(values: dict) -> ViscousTerms:
    """The damping time tau_d (s) of the chain's values ({key: SI value})."""
    return ViscousTerms(damping_time=values["damping_time"])


LAW = ContactLaw(
    "kuwabara-kono",
    "viscoelastic F = A delta^(n-1) (delta + tau_d d(delta)/dt), never attractive (Kuwabara & Kono, "
    "Jpn. J. Appl. Phys. 26, 1230 (1987); Brilliantov et al., Phys. Rev. E 53, 5382 (1996)); tau_d is "
    "the material's damping time (chain.damping_time)",
    (DAMPING_TIME,), viscous_terms, KUWABARA_KONO)
