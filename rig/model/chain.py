"""A chain of parts (what is simulated) and its flat-array form for the kernels.

Axis x points down the tube. Beads are numbered from the top, 0-based: bead 0 is the top
(magnetic) bead. Contact k is the contact *above* bead k: contact 0 is striker/bead 0,
contact n_beads is bead n_beads-1 / wall.

The chain starts in static equilibrium, nothing moving before the impact (statics.py).
"""
from __future__ import annotations

import copy
import functools
import math
from dataclasses import dataclass

import numpy as np

from rig.errors import invalid
from rig.memo import computed_once
from rig.model import contact_yield
from rig.model.laws import contact_law as lookup_law
from rig.model.laws import law_values
from rig.model.parts import Bead, Striker, Wall
from rig.model.statics import (
    contact_constants_of,
    equilibrium_positions_of,
    follows_law,
    static_forces_of,
    static_overlaps_of,
)
from rig.units import quantity

STANDARD_GRAVITY = 9.80665  # m/s^2


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
    contact_law: a law of rig.model.laws ("hertz", the default, conservative;
    "kuwabara-kono" with damping_time (s); "dashpot" with contact_damping (kg/s);
    "powerlaw-dashpot" with dashpot_gamma and dashpot_exponent); ``contact``: the laws'
    parameters by scene key (rig.model.laws.PARAMETERS, each an attribute of the chain),
    among them the elastic exponent contact_exponent (3/2: Hertz) matched to Hertz at
    reference_force (N). The contacts that touch a bead of the chain's material follow the
    law (follows_law).
    drag (kg/s), friction (N), slip_speed (m/s): what the holder's wall does to each bead
    (rig.model.apparatus.Holder); 0: nothing. hold (s): how long the top force rested on the
    chain before the shot (a yielding law flattens the loaded contacts at its static yield).
    """

    # the laws' parameters (rig.model.laws.PARAMETERS, SI units), set from ``contact`` in __init__
    contact_exponent: float
    reference_force: float
    damping_time: float
    contact_damping: float
    dashpot_gamma: float
    dashpot_exponent: float
    yield_force: float
    yield_pressure: float
    yield_rate_exponent: float
    yield_reference_rate: float
    static_yield_ratio: float

    def __init__(self, beads, *, striker: Striker | None = None, wall: Wall | None = None,
                 gravity: float = STANDARD_GRAVITY, top_force=0.0,
                 contact_law: str = "hertz", drag=0.0, friction=0.0, slip_speed=1e-3, hold=0.0, **contact):
        if isinstance(beads, (str, bytes)) or not hasattr(beads, "__iter__"):
            raise invalid("chain.beads", beads, "a list of Beads")
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
        self.top_force: float | ForceSchedule
        if isinstance(top_force, ForceSchedule):
            self.top_force = top_force
        else:
            self.top_force = quantity(top_force, "N", "chain.top_force", bare_ok=True)
        self.law = lookup_law(contact_law)
        self.contact_parameters = law_values(self.law, contact)
        for key, value in self.contact_parameters.items():  # chain.damping_time, chain.contact_exponent, ...
            setattr(self, key, value)
        if self.contact_parameters.get("yield_pressure", 0.0) > 0 and self.contact_exponent != 1.5:
            raise invalid("chain.yield_pressure", self.yield_pressure,
                          f"a yield pressure needs Hertz contacts (chain.contact_exponent = 1.5, here "
                          f"{self.contact_exponent:g}); with another exponent give chain.yield_force, every "
                          "contact's yield force")
        contact_yield.say_yield_pressure(self)
        self.hold = quantity(hold, "s", "magnet.hold", bare_ok=True)
        if not self.hold >= 0:
            raise invalid("magnet.hold", hold, "must be >= 0 s")
        if self.hold > 0 and not self.has_top_force:
            raise invalid("magnet.hold", hold, "a static hold needs the magnet's load (magnet.force > 0 N), "
                                               "or leave it 0 s")
        self.drag = quantity(drag, "kg/s", "holder.drag", bare_ok=True)
        self.friction = quantity(friction, "N", "holder.friction", bare_ok=True)
        self.slip_speed = quantity(slip_speed, "m/s", "holder.slip_speed", bare_ok=True)
        for name, value, allowed in (("drag", self.drag, "must be >= 0 kg/s"), ("friction", self.friction,
                                     "must be >= 0 N"), ("slip_speed", self.slip_speed, "must be > 0 m/s")):
            if not (value > 0 or (value == 0 and name != "slip_speed")):
                raise invalid(f"holder.{name}", value, allowed)
        self._check_equilibrium()

    # --- geometry and statics -------------------------------------------------------
    @property
    def n_beads(self) -> int:
        return len(self.beads)

    @property
    def n_contacts(self) -> int:
        """Contacts 0..n_beads, and the rod of a compliant wall after them."""
        return self.n_beads + 1 + (1 if self.wall is not None and self.wall.compliant else 0)

    @property
    def masses(self) -> np.ndarray:
        return np.array([b.mass for b in self.beads])

    @property
    def body_masses(self) -> np.ndarray:
        """The beads' masses (kg), and a compliant wall's plate last."""
        if self.wall is not None and self.wall.plate_mass is not None:  # a compliant wall
            return np.append(self.masses, self.wall.plate_mass)
        return self.masses

    def contact_exponents(self) -> np.ndarray:
        """Exponent n of each contact's elastic law A delta^n (follows_law: the chain's
        contact_exponent; 3/2 for the others, 1 for a compliant wall's rod)."""
        n = np.where(follows_law(self), self.contact_exponent, 1.5)
        if self.wall is not None and self.wall.compliant:
            n[-1] = 1.0
        return n

    def contact_dissipation(self) -> np.ndarray:
        """(3, contacts): each contact's viscous terms (rig.model.laws.ViscousTerms):
        Kuwabara-Kono damping time (s), dashpot coefficient gamma (N (s/m)^alpha; kg/s for a
        linear one) and exponent alpha; (0, 0, 1) where it does not follow the chain's law."""
        law = follows_law(self)
        terms = self.law.viscous(self.contact_parameters)
        return np.array([np.where(law, terms.damping_time, 0.0), np.where(law, terms.dashpot, 0.0),
                         np.where(law, terms.dashpot_exponent, 1.0)])

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
        """Contact constants of contacts 0..n_beads and a compliant wall's rod (nan where there
        is no partner; statics.contact_constants_of)."""
        return self._cached("A", lambda: contact_constants_of(self))

    def static_forces(self) -> np.ndarray:
        """Static contact forces (N) of contacts 0..n_beads: weight above plus top force."""
        return self._cached("F0", lambda: static_forces_of(self.body_masses, self.gravity, self.initial_top_force))

    def static_overlaps(self) -> np.ndarray:
        """Static overlaps (m), d0 = (F/A)^(1/n) ((F/A)^(2/3): Hertz); 0 where a contact
        carries nothing; a contact flattened by a static hold rests deeper (contact_memory)."""
        return self._at_rest[1]

    def rest_state(self) -> np.ndarray:
        """The kernels' memory of the chain's contacts at rest (contact_memory's state of its
        constants and static forces)."""
        return self._at_rest[0]

    prior: np.ndarray | None = None
    """The contacts' memory a previous shot left (STATE_ROWS, contacts; after_shot), or None:
    contacts as the static load alone left them."""

    def after_shot(self, solution) -> Chain:
        """This chain as it rests after the shot ``solution`` solved (a single shot's solve of
        this chain, which carries its contacts' memory at the end): the contacts keep their
        flattening (permanent overlaps, enlarged radii, elastic limits) and rest on their
        elastic curves under the static load, as a real chain does between two shots
        (rig.model.laws.thornton.rest_after). The same chain where no contact yields."""
        from rig.model.laws.thornton import STATE_ROWS

        if solution.memory is None:
            raise invalid("solution", "a batch's", "a single shot's solve of this chain (it keeps the memory)")
        off = solution.problem.offset
        memory = np.array(solution.memory[:, off:off + self.n_contacts], dtype=float)
        if memory.shape != (len(STATE_ROWS), self.n_contacts):
            raise invalid("solution", memory.shape, f"a solve of this chain ({self.n_contacts} contacts)")
        chain = copy.copy(self)
        chain.__dict__ = {k: v for k, v in self.__dict__.items() if k not in ("_at_rest", "_computed")}
        chain.prior = memory
        return chain

    @functools.cached_property
    def _at_rest(self) -> tuple:
        """(rest_state, static_overlaps), computed once, read-only."""
        state, d0, _ = self.contact_memory(self.contact_constants(), self.static_forces())
        for a in (state, d0):
            a.setflags(write=False)
        return state, d0

    def contact_memory(self, A, F) -> tuple:
        """(state, d0, hold_work) of contacts of constants A (N/m^n) carrying static forces F
        (N) (arrays (..., contacts)): the kernels' memory of each contact
        (rig.model.laws.thornton.STATE_ROWS, first axis), the static overlaps (m) and the
        plastic work (J) a static hold took. Contacts that do not follow a yielding law are
        elastic and as new."""
        from rig.model.laws.thornton import NO_YIELD, STATE_ROWS, initial_state, rest_after

        n = self.contact_exponents()
        d_el = static_overlaps_of(A, F, n)
        if self.prior is not None:  # the memory a previous shot left, at rest under the static load again
            prior = self.prior if np.ndim(A) == 1 else np.broadcast_to(
                self.prior[:, None, :], (len(STATE_ROWS),) + np.shape(A))
            state, d0 = rest_after(prior, n, F, d_el)
            return state, d0, np.zeros(np.shape(A))
        terms = self.yield_terms or NO_YIELD
        live = follows_law(self) & np.isfinite(A)
        state, d0, work = initial_state(np.where(live, A, 0.0), n, np.where(live, F, 0.0), d_el, terms,
                                        self.contact_yield_forces(A), self.hold)
        ap = STATE_ROWS.index("unloading_constant")
        state[ap] = np.where(live, state[ap], np.where(np.isfinite(A), A, 0.0))  # as new: A_p = A
        return state, np.where(live, d0, d_el), work

    @property
    def yield_terms(self):
        """Its law's rig.model.laws.thornton.YieldTerms, or None where the law never yields."""
        return self.law.yielding(self.contact_parameters) if self.law.yielding else None

    def contact_yield_pressure(self, A=None):
        """The yield pressure p_y (Pa) of its contacts, or None (rig.model.contact_yield)."""
        return contact_yield.yield_pressure(self, A)

    def contact_yield_forces(self, A=None) -> np.ndarray:
        """Each contact's yield force F_y (N) (rig.model.contact_yield)."""
        return contact_yield.yield_forces(self, A)

    def contact_yield_rates(self) -> tuple:
        """(m, r_ref): each contact's yield rate exponent and reference closing rate (m/s)
        (rig.model.laws.thornton); (0, 1) where it does not follow a yielding law."""
        from rig.model.laws.thornton import NO_YIELD

        terms = self.yield_terms or NO_YIELD
        law = follows_law(self)
        return np.where(law, terms.rate_exponent, 0.0), np.where(law, terms.reference_rate, 1.0)

    def equilibrium_positions(self) -> np.ndarray:
        """Bead centres at equilibrium (m, down from bead 0's centre)."""
        return self._cached("x", lambda: equilibrium_positions_of([b.radius for b in self.beads],
                                                                  self.static_overlaps()))

    def impact_overlap(self) -> float:
        """The striker's overlap with the top bead (m) if all its kinetic energy went into
        their contact: (1/2) m v^2 = A delta^(n+1) / (n+1), delta = ((n+1) m v^2 / (2A))^(1/(n+1));
        an upper bound of the first contact's largest overlap (0 without a striker)."""
        if self.striker is None:
            return 0.0
        A, n = float(self.contact_constants()[0]), float(self.contact_exponents()[0])
        return ((n + 1) * self.striker.mass * self.striker.velocity ** 2 / (2 * A)) ** (1 / (n + 1))

    def wall_position(self) -> float:
        """The wall surface (m, down from bead 0's centre; a compliant wall's plate at
        rest); nan without a wall."""
        if self.wall is None:
            return math.nan
        return self.equilibrium_positions()[-1] + self.beads[-1].radius - self.static_overlaps()[self.n_beads]

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
        if not (0 <= k < self.n_contacts) or not np.isfinite(A[k]):
            raise invalid(what, k, f"no such contact in a chain of {self.n_beads} beads "
                                   f"(contacts 0..{self.n_contacts - 1}; 0 needs a striker, "
                                   f"{self.n_beads} a wall, {self.n_beads + 1} a compliant wall's rod)")

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
        """What the wall sensor reads: the wall contact's force, or a compliant wall's rod's."""
        if self.wall is None:
            raise invalid("probe.wall", None, "this chain has no wall")
        return Probe((self.n_contacts - 1,), (1.0,))
