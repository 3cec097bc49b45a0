"""Each contact's yield in an elastic-plastic chain (rig.model.laws.thornton): a material
yields at a pressure, so each contact at its own force.

Hertz's centre pressure reaches the yield pressure p_y at F_y = pi^3 R*^2 p_y^3 / (6 E*^2)
(thornton.pressure_yield_force): each contact's force follows from its own reduced radius
and moduli (a steel-PTFE contact yields at about 0.26 of the PTFE-PTFE force).
chain.yield_pressure gives p_y; chain.yield_force, the older key, is the force of the
chain's own bead-bead contacts, read as the pressure that yields them there, and said so
once a process (a RigNote). With a power law of another exponent there is no Hertz
pressure: chain.yield_force is then every contact's force.
"""
from __future__ import annotations

import warnings

import numpy as np

from rig.errors import RigNote
from rig.model.statics import follows_law, reduced_radii_of

SAID: set = set()  # what was said once a process ("yield_force": the note on its reading as a pressure)


def reference_contact(chain) -> int | None:
    """The contact chain.yield_force names: the first between two beads of the chain's
    material (None: the chain has no such pair)."""
    b = chain.beads
    return next((k for k in range(1, chain.n_beads) if b[k - 1].kind != "magnetic" and b[k].kind != "magnetic"),
                None)


def yield_pressure(chain, A=None):
    """The yield pressure p_y (Pa; per shot where A is an array of shots' contact constants)
    of the chain's contacts: chain.yield_pressure, or the pressure at which chain.yield_force
    yields the chain's bead-bead contacts; None where the law does not yield, the contacts
    are not Hertz's, or no bead-bead contact names it."""
    from rig.model.laws.thornton import yield_pressure_of

    terms = chain.yield_terms
    if terms is None or chain.contact_exponent != 1.5:
        return None
    if terms.yield_pressure > 0:
        return terms.yield_pressure
    k = reference_contact(chain)
    if terms.yield_force == 0 or k is None:
        return None
    A = chain.contact_constants() if A is None else np.asarray(A, float)
    return yield_pressure_of(terms.yield_force, float(reduced_radii_of(chain)[k]), A[..., k])


def yield_forces(chain, A=None) -> np.ndarray:
    """Each contact's yield force F_y (N) at the reference closing rate (contacts 0..n, last
    axis; per shot where A, the contacts' constants, is an array of shots'): the force at
    which the yield pressure is reached in that contact, F_y = pi^3 R*^2 p_y^3 / (6 E*^2)
    from its own radius and moduli; chain.yield_force for every contact where there is no
    pressure (another exponent); 0 where it never yields."""
    from rig.model.laws.thornton import pressure_yield_force

    A = chain.contact_constants() if A is None else np.asarray(A, float)
    terms = chain.yield_terms
    if terms is None:
        return np.zeros(A.shape)
    p = yield_pressure(chain, A)
    if p is None:
        return np.full(A.shape, terms.yield_force)
    p = np.asarray(p, float)[..., None] if np.ndim(p) else float(p)
    return pressure_yield_force(p, reduced_radii_of(chain), A)


def say_yield_pressure(chain) -> None:
    """Where chain.yield_force (a force) is read as the pressure that yields the chain's
    bead-bead contacts, say so, once a process (a RigNote), with the pressure and the other
    contacts' forces of the first chain read so."""
    if "yield_force" in SAID or chain.yield_terms is None or not chain.yield_force > 0:
        return
    p = yield_pressure(chain)
    if p is None:
        return
    forces = yield_forces(chain)
    live = follows_law(chain) & np.isfinite(forces)
    names = {0: "the striker's", chain.n_beads: "the wall's"}
    if chain.beads[0].kind == "magnetic":
        names[1] = "the magnetic bead's"
    others = [f"{name} {forces[k]:.3g} N" for k, name in sorted(names.items()) if k < forces.size and live[k]]
    SAID.add("yield_force")
    warnings.warn(f"chain.yield_force = {chain.yield_force:g} N is read as the yield pressure of the chain's "
                  f"bead-bead contacts, p_y = {p / 1e6:.4g} MPa (chain.yield_pressure); at that pressure the "
                  f"other contacts yield at their own forces"
                  f"{' (' + ', '.join(others) + ')' if others else ''}; rig theory --yield-force lists them",
                  RigNote, stacklevel=3)
