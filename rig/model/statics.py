"""A chain's contacts and static equilibrium, as arrays (a last axis over the contacts or
beads, any shots before it), for one chain or many shots of one layout.

Static equilibrium (Daraio et al. 2006): the contact below bead j carries the weight of
beads 0..j plus the top force, F_j = g sum_{i<=j} m_i + F_top; the striker just touches
(contact 0 carries nothing). Overlaps follow by inverting the contact law,
d0 = (F/A)^(1/n) ((F/A)^(2/3) for Hertz), so nothing moves before impact.
"""
from __future__ import annotations

import math
from typing import Any, Protocol

import numpy as np

from rig.model.contact import hertz_constant, power_law_constant, static_overlaps
from rig.model.parts import Bead, Striker, Wall


class Layout(Protocol):
    """What the statics read of a chain (rig.model.chain.Chain is one): its parts, in order
    from the top, and its contact law's elastic exponent, matched to Hertz at
    reference_force (N)."""

    @property
    def beads(self) -> tuple[Bead, ...]: ...
    @property
    def striker(self) -> Striker | None: ...
    @property
    def wall(self) -> Wall | None: ...
    @property
    def contact_exponent(self) -> float: ...
    @property
    def reference_force(self) -> float: ...
    @property
    def n_beads(self) -> int: ...
    @property
    def n_contacts(self) -> int: ...


def follows_law(chain: Layout) -> np.ndarray:
    """Which contacts (0..n_beads, and the rod of a compliant wall) follow the chain's
    contact law (its exponent and dissipation): those that touch a bead of the chain's
    material (not the magnetic bead). The others (a striker on the magnetic bead, the rod)
    keep their own: Hertz, and linear for the rod."""
    chain_bead = np.array([x.kind != "magnetic" for x in chain.beads], dtype=bool)
    out = np.zeros(chain.n_contacts, dtype=bool)
    out[:chain_bead.size + 1] = np.append(False, chain_bead) | np.append(chain_bead, False)  # the bead above, below
    return out


def reduced_radii_of(chain: Layout) -> np.ndarray:
    """R* = R1 R2 / (R1 + R2) (m) of contacts 0..n_beads of ``chain`` (the sphere's own
    radius on a flat: the striker's face, the wall; nan where there is no partner), the
    radii of contact_constants_of's Hertz constants."""
    b = chain.beads
    R = np.full(chain.n_contacts, np.nan)
    if chain.striker is not None:
        R[0] = b[0].radius
    for k in range(1, chain.n_beads):
        R[k] = b[k - 1].radius * b[k].radius / (b[k - 1].radius + b[k].radius)
    if chain.wall is not None:
        R[chain.n_beads] = b[-1].radius
    return R


def contact_constants_of(chain: Layout, E=None, nu=None) -> np.ndarray:
    """Contact constants of contacts 0..n_beads of ``chain`` (and the rod of a compliant
    wall; last axis; nan where there is no partner): Hertz constants (N/m^1.5), the
    power-law constant (N/m^n, power_law_constant) for the contacts that follow a law of
    another exponent, the rod's stiffness (N/m). E, nu (Pa, -; arrays of shots, or None):
    the elastic constants of its beads' material (every bead but a magnetic one) in place
    of the material's own."""
    b = chain.beads
    plain = next((x.material for x in b if x.kind != "magnetic"), None)

    def elastic(m) -> tuple[Any, Any]:
        if m is plain and E is not None:
            return np.asarray(E, dtype=float), np.asarray(nu, dtype=float)
        return m.E, m.nu

    shape = () if E is None else np.shape(E)
    A = np.full(shape + (chain.n_contacts,), np.nan)
    if chain.striker is not None:
        A[..., 0] = hertz_constant(*elastic(chain.striker.material), math.inf, *elastic(b[0].material), b[0].radius)
    pairs = {}  # a chain repeats the same pair of beads many times
    for k in range(1, chain.n_beads):
        up, down = b[k - 1], b[k]
        key = (id(up.material), up.diameter, id(down.material), down.diameter)
        if key not in pairs:
            pairs[key] = hertz_constant(*elastic(up.material), up.radius, *elastic(down.material), down.radius)
        A[..., k] = pairs[key]
    if chain.wall is not None:
        k = chain.n_beads
        A[..., k] = hertz_constant(*elastic(b[-1].material), b[-1].radius, *elastic(chain.wall.material), math.inf)
        if chain.wall.compliant:
            A[..., k + 1] = chain.wall.rod_stiffness
    if chain.contact_exponent != 1.5:
        law = follows_law(chain)
        A[..., law] = power_law_constant(A[..., law], chain.contact_exponent, chain.reference_force)
    return A


def static_forces_of(masses, gravity: float, top_force) -> np.ndarray:
    """Static contact forces (N) of contacts 0..n (last axis) of chains of body masses
    ``masses`` (kg, (..., n): the beads, and the plate of a compliant wall last): F_k =
    gravity x the mass of bodies 0..k-1 + the top force; contact 0 (the striker's) carries
    nothing."""
    masses = np.asarray(masses, dtype=float)
    F = np.zeros(masses.shape[:-1] + (masses.shape[-1] + 1,))
    F[..., 1:] = gravity * np.cumsum(masses, axis=-1) + np.asarray(top_force, dtype=float)[..., None]
    return F


def static_overlaps_of(A, F, n=1.5) -> np.ndarray:
    """Static overlaps (m) d0 = (F/A)^(1/n) of contacts of constants A carrying F (N), of
    exponents n (3/2: Hertz; an array along the last axis); 0 where a contact carries
    nothing or has no partner (A nan)."""
    d0 = np.zeros_like(F)
    ok = np.isfinite(A) & (F > 0)
    n = np.broadcast_to(np.asarray(n, dtype=float), np.shape(F))
    d0[ok] = static_overlaps(A[ok], F[ok], n[ok])
    return d0


def equilibrium_positions_of(radii, d0) -> np.ndarray:
    """Bead centres (m, down from bead 0's centre; last axis) of beads of ``radii`` (m)
    resting with static overlaps d0 ((..., n + 1))."""
    n = len(radii)
    x = np.zeros(np.shape(d0)[:-1] + (n,))
    for k in range(1, n):
        x[..., k] = x[..., k - 1] + radii[k - 1] + radii[k] - d0[..., k]
    return x
