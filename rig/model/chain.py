"""A chain of parts (what is simulated) and its flat-array form for the kernels.

Axis x points down the tube. Beads are numbered from the top, 0-based: bead 0 is the top
(magnetic) bead. Contact k is the contact *above* bead k: contact 0 is striker/bead 0,
contact n_beads is bead n_beads-1 / wall.

Static equilibrium (Daraio et al. 2006): the contact below bead j carries the weight of
beads 0..j plus the top force, F_j = g sum_{i<=j} m_i + F_top; the striker just touches
(contact 0 carries nothing). Overlaps follow by inverting the Hertz law,
d0 = (F/A)^(2/3), so nothing moves before impact.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rig.errors import invalid
from rig.memo import computed_once
from rig.model.contact import contact_law as lookup_law
from rig.model.contact import hertz_constant, static_overlaps
from rig.model.parts import Bead, Striker, Wall
from rig.units import quantity

STANDARD_GRAVITY = 9.80665  # m/s^2


def contact_constants_of(chain: "Chain", E=None, nu=None) -> np.ndarray:
    """Hertz constants (N/m^1.5) of contacts 0..n_beads of ``chain`` (last axis; nan where
    there is no partner); E, nu (Pa, -; arrays of shots, or None): the elastic constants of
    its beads' material (every bead but a magnetic one) in place of the material's own."""
    b = chain.beads
    plain = next((x.material for x in b if x.kind != "magnetic"), None)

    def elastic(m):
        if m is plain and E is not None:
            return np.asarray(E, dtype=float), np.asarray(nu, dtype=float)
        return m.E, m.nu

    shape = () if E is None else np.shape(E)
    A = np.full(shape + (chain.n_beads + 1,), np.nan)
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
        A[..., -1] = hertz_constant(*elastic(b[-1].material), b[-1].radius, *elastic(chain.wall.material), math.inf)
    return A


def static_forces_of(masses, gravity: float, top_force) -> np.ndarray:
    """Static contact forces (N) of contacts 0..n (last axis) of chains of bead masses
    ``masses`` (kg, (..., n)): F_k = gravity x the mass of beads 0..k-1 + the top force;
    contact 0 (the striker's) carries nothing."""
    masses = np.asarray(masses, dtype=float)
    F = np.zeros(masses.shape[:-1] + (masses.shape[-1] + 1,))
    F[..., 1:] = gravity * np.cumsum(masses, axis=-1) + np.asarray(top_force, dtype=float)[..., None]
    return F


def static_overlaps_of(A, F) -> np.ndarray:
    """Static overlaps (m) d0 = (F/A)^(2/3) of contacts of constants A carrying F (N);
    0 where a contact carries nothing or has no partner (A nan)."""
    d0 = np.zeros_like(F)
    ok = np.isfinite(A) & (F > 0)
    d0[ok] = static_overlaps(A[ok], F[ok])
    return d0


def equilibrium_positions_of(radii, d0) -> np.ndarray:
    """Bead centres (m, down from bead 0's centre; last axis) of beads of ``radii`` (m)
    resting with static overlaps d0 ((..., n + 1))."""
    n = len(radii)
    x = np.zeros(np.shape(d0)[:-1] + (n,))
    for k in range(1, n):
        x[..., k] = x[..., k - 1] + radii[k - 1] + radii[k] - d0[..., k]
    return x


@dataclass(frozen=True)
class ForceSchedule:
    """A force varying in time, piecewise linear between (times[i], forces[i]) (s, N),
    held at the end values outside the table."""

    times: tuple
    forces: tuple

    def __post_init__(self):
        t = np.asarray(self.times, dtype=float)
        f = np.asarray(self.forces, dtype=float)
        if t.ndim != 1 or t.size < 1 or t.shape != f.shape:
            raise invalid("top_force.times", self.times, "times and forces: equal-length lists")
        if np.any(np.diff(t) <= 0) or not np.all(np.isfinite(t)) or not np.all(np.isfinite(f)):
            raise invalid("top_force.times", self.times, "finite, strictly increasing times")
        object.__setattr__(self, "times", tuple(t))
        object.__setattr__(self, "forces", tuple(f))

    def at(self, t: float) -> float:
        return float(np.interp(t, self.times, self.forces))


@dataclass(frozen=True)
class Probe:
    """A recorded force: sum of weight * contact force over (contact, weight) pairs."""

    contacts: tuple
    weights: tuple


class Chain:
    """Beads between an optional striker (top) and an optional wall (bottom).

    gravity: acceleration along +x (m/s^2); 0 for a horizontal chain.
    top_force: constant force (N) or ForceSchedule pulling bead 0 down (the ring magnet).
    contact_law: "hertz" (default, conservative) or "kuwabara-kono" with damping_time (s).
    """

    def __init__(self, beads, *, striker: Striker | None = None, wall: Wall | None = None,
                 gravity: float = STANDARD_GRAVITY, top_force=0.0,
                 contact_law: str = "hertz", damping_time=0.0):
        beads = list(beads)
        if not beads:
            raise invalid("chain.beads", beads, "a chain needs at least one bead")
        for i, b in enumerate(beads):
            if not isinstance(b, Bead):
                raise invalid(f"chain.beads[{i}]", b, "expected a Bead")
        if striker is not None and not isinstance(striker, Striker):
            raise invalid("chain.striker", striker, "expected a Striker or None")
        if wall is not None and not isinstance(wall, Wall):
            raise invalid("chain.wall", wall, "expected a Wall or None")
        self.beads = tuple(beads)
        self.striker = striker
        self.wall = wall
        self.gravity = quantity(gravity, "m/s^2", "chain.gravity", bare_ok=True)
        if self.gravity < 0:
            raise invalid("chain.gravity", gravity, "must be >= 0 m/s^2 (x points down)")
        if isinstance(top_force, ForceSchedule):
            self.top_force = top_force
        else:
            self.top_force = quantity(top_force, "N", "chain.top_force", bare_ok=True)
        self.law = lookup_law(contact_law)
        self.damping_time = quantity(damping_time, "s", "chain.damping_time", bare_ok=True)
        if self.damping_time < 0:
            raise invalid("chain.damping_time", damping_time, "must be >= 0 s")
        if self.law.dissipative and self.damping_time == 0:
            raise invalid("chain.damping_time", damping_time,
                          f"contact law {self.law.name!r} needs a damping time > 0 s")
        self._check_equilibrium()

    # --- geometry and statics -------------------------------------------------------
    @property
    def n_beads(self) -> int:
        return len(self.beads)

    @property
    def masses(self) -> np.ndarray:
        return np.array([b.mass for b in self.beads])

    @property
    def initial_top_force(self) -> float:
        tf = self.top_force
        return tf.at(0.0) if isinstance(tf, ForceSchedule) else tf

    @property
    def has_top_force(self) -> bool:
        tf = self.top_force
        return isinstance(tf, ForceSchedule) or tf != 0.0

    def _cached(self, name, compute):
        """A chain does not change after construction: its static geometry is computed once."""
        return computed_once(self, name, compute)

    def contact_constants(self) -> np.ndarray:
        """Hertz constants (N/m^1.5) of contacts 0..n_beads (nan where there is no partner)."""
        return self._cached("A", self._contact_constants)

    def _contact_constants(self) -> np.ndarray:
        return contact_constants_of(self)

    def static_forces(self) -> np.ndarray:
        """Static contact forces (N) of contacts 0..n_beads: weight above plus top force."""
        return self._cached("F0", self._static_forces)

    def _static_forces(self) -> np.ndarray:
        return static_forces_of(self.masses, self.gravity, self.initial_top_force)

    def static_overlaps(self) -> np.ndarray:
        """Static overlaps (m), d0 = (F/A)^(2/3); 0 where a contact carries nothing."""
        return self._cached("d0", self._static_overlaps)

    def _static_overlaps(self) -> np.ndarray:
        return static_overlaps_of(self.contact_constants(), self.static_forces())

    def equilibrium_positions(self) -> np.ndarray:
        """Bead centres at equilibrium (m, down from bead 0's centre)."""
        return self._cached("x", self._equilibrium_positions)

    def _equilibrium_positions(self) -> np.ndarray:
        return equilibrium_positions_of([bead.radius for bead in self.beads], self.static_overlaps())

    def wall_position(self) -> float:
        """The wall surface (m, down from bead 0's centre); nan without a wall."""
        if self.wall is None:
            return math.nan
        return self.equilibrium_positions()[-1] + self.beads[-1].radius - self.static_overlaps()[-1]

    def _check_equilibrium(self):
        loaded = self.gravity > 0 or self.initial_top_force != 0.0
        if loaded and self.wall is None:
            raise invalid("chain.wall", None,
                          "a chain under gravity or a top force needs a wall to rest on")
        F = self.static_forces()
        if np.any(F[1:] < 0):
            k = int(np.argmax(F[1:] < 0)) + 1
            raise invalid("chain.top_force", self.initial_top_force,
                          f"no static equilibrium: contact {k} would pull ({F[k]:.4g} N)")

    # --- probes -------------------------------------------------------------------
    def _check_contact(self, k: int, what: str):
        A = self.contact_constants()
        if not (0 <= k <= self.n_beads) or not np.isfinite(A[k]):
            raise invalid(what, k, f"no such contact in a chain of {self.n_beads} beads "
                                   f"(contacts 0..{self.n_beads}; 0 needs a striker, "
                                   f"{self.n_beads} a wall)")

    def contact_probe(self, k: int) -> Probe:
        """The force of contact k (the contact above bead k)."""
        self._check_contact(k, "probe.contact")
        return Probe((k,), (1.0,))

    def gauge_probe(self, j: int) -> Probe:
        """What a rigid gauge bead j reads: the mean of its two contact forces."""
        if not 0 <= j < self.n_beads:
            raise invalid("probe.gauge_bead", j, f"beads are 0..{self.n_beads - 1}")
        A = self.contact_constants()
        pairs = [(k, 0.5) for k in (j, j + 1) if np.isfinite(A[k])]
        return Probe(tuple(k for k, _ in pairs), tuple(w for _, w in pairs))

    def wall_probe(self) -> Probe:
        """The wall contact force."""
        if self.wall is None:
            raise invalid("probe.wall", None, "this chain has no wall")
        return Probe((self.n_beads,), (1.0,))
