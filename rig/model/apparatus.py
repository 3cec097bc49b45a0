"""The apparatus around the chain: the holder tube and the ring magnet."""
from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from rig.errors import RigError, invalid
from rig.model.chain import STANDARD_GRAVITY, ForceSchedule


@dataclass(frozen=True)
class Holder:
    """The PTFE tube: bore and outer diameter (m), length (m), vertical or horizontal, and
    what the tube's wall does to each bead sliding in it (every bead; not the striker):

        F = -drag v - friction tanh(v / slip_speed)

    a viscous drag (kg/s) and Coulomb friction (N) smoothed over slip_speed (m/s), so that
    a bead at rest feels none and the static equilibrium is the frictionless one. Both 0
    by default (no cost in the solver when off)."""

    bore: float = 5e-3
    outer_diameter: float = 10e-3
    length: float = 0.5
    vertical: bool = True
    drag: float = 0.0
    friction: float = 0.0
    slip_speed: float = 1e-3

    def __post_init__(self):
        if not self.bore > 0:
            raise invalid("holder.bore", self.bore, "must be > 0 m")
        if not self.outer_diameter > self.bore:
            raise invalid("holder.outer_diameter", self.outer_diameter, f"must exceed the bore {self.bore} m")
        if not self.length > 0:
            raise invalid("holder.length", self.length, "must be > 0 m")
        for name, unit in (("drag", "kg/s"), ("friction", "N")):
            if not getattr(self, name) >= 0:
                raise invalid(f"holder.{name}", getattr(self, name), f"must be >= 0 {unit}")
        if not self.slip_speed > 0:
            raise invalid("holder.slip_speed", self.slip_speed, "must be > 0 m/s")

    @property
    def gravity(self) -> float:
        """Acceleration along the tube axis (m/s^2): g when vertical, 0 when horizontal."""
        return STANDARD_GRAVITY if self.vertical else 0.0

    def check(self, beads, striker=None):
        """Refuse parts that do not fit the bore, and a stack longer than the tube."""
        for i, b in enumerate(beads):
            if b.diameter > self.bore:
                raise invalid(f"chain.beads[{i}].diameter", b.diameter,
                              f"wider than holder.bore = {self.bore * 1e3:g} mm")
        if striker is not None and striker.diameter > self.bore:
            raise invalid("striker.diameter", striker.diameter,
                          f"wider than holder.bore = {self.bore * 1e3:g} mm")
        if striker is not None and striker.length > self.length:  # the striker alone: its mass or the tube
            raise RigError(f"striker.mass = {striker.mass:g} kg and holder.length = {self.length:g} m: a "
                           f"{striker.diameter * 1e3:g} mm {striker.material.name} striker of that mass is "
                           f"{striker.length:.4g} m long, longer than the tube")
        stack = sum(b.diameter for b in beads) + (striker.length if striker else 0.0)
        if stack > self.length:
            raise invalid("holder.length", self.length,
                          f"the chain and striker need {stack:.4g} m of tube")


# Published ring (Daraio et al. 2006): NdFeB, inner 11.43 mm, outer 53.34 mm, 242.2 g.
# Its thickness is not published; 12.7 mm is assumed (a standard 1/2 inch ring).
RING_INNER, RING_OUTER, RING_THICKNESS, RING_MASS = 11.43e-3, 53.34e-3, 12.7e-3, 0.2422
LONG_HOLD = 600.0  # s: a ring left resting on the bead between shots (minutes; any hold > 0 s flattens the same)


@functools.lru_cache(maxsize=8)
def _pull_profile(inner: float, outer: float, thickness: float):
    """(z, shape) of the axial pull on a small soft-iron ball on the ring's axis.

    The on-axis field of an axially magnetised ring (radii a < b, thickness L, centre at 0)
    is B(z) ~ f(z + L/2) - f(z - L/2), f(u) = u/sqrt(u^2 + b^2) - u/sqrt(u^2 + a^2); the
    force on a small linear magnetisable sphere is ~ d(B^2)/dz (e.g. Jackson, Classical
    Electrodynamics, section 5.7). z: ring centre below the ball (m); shape peaks at 1.
    """
    a, b, L = inner / 2, outer / 2, thickness
    z = np.linspace(0.0, 6 * outer, 6001)

    def f(u):
        return u / np.sqrt(u * u + b * b) - u / np.sqrt(u * u + a * a)

    ball = -z  # the ball's coordinate in the ring frame
    B = f(ball + L / 2) - f(ball - L / 2)
    pull = np.gradient(B * B, ball)  # towards the ring (down) is positive
    return z, pull / pull.max()


@dataclass(frozen=True)
class RingMagnet:
    """Non-contact precompression: a ring magnet around the tube pulls the top bead down.

    Give ``force`` (N) directly, or ``position`` (m, ring centre below the bead's centre)
    with ``peak_force`` (N, the largest pull along the axis; assumed 6 N) to take the force
    from the on-axis pull profile, so that sliding the ring changes the force. A ring left
    to hang on the bead carries its weight: 0.2422 kg x g = 2.38 N, the published
    precompression. ``schedule``: [(t (s), F (N)), ...] varies the force in time
    (piecewise linear). ``hold`` (s): how long its force rested on the chain before the
    shot (0: put on at the shot; not given: LONG_HOLD, the ring resting on the bead between
    shots); a contact law that yields flattens the loaded contacts at its static yield
    (rig.model.laws.thornton), any hold > 0 s the same.
    """

    force: float | None = None
    position: float | None = None
    peak_force: float = 6.0
    schedule: tuple | None = None
    mass: float = RING_MASS
    hold: float | None = None

    def __post_init__(self):
        given = [k for k in ("force", "position", "schedule") if getattr(self, k) is not None]
        if len(given) != 1:
            raise invalid("magnet", given or None, "give exactly one of force, position, schedule")
        if self.force is not None and not self.force >= 0:
            raise invalid("magnet.force", self.force, "must be >= 0 N")
        if self.position is not None and not 0 <= self.position <= 6 * RING_OUTER:
            raise invalid("magnet.position", self.position, f"allowed 0 <= position <= {6 * RING_OUTER:.3g} m")
        if not self.peak_force > 0:
            raise invalid("magnet.peak_force", self.peak_force, "must be > 0 N")
        if self.hold is not None and not self.hold >= 0:
            raise invalid("magnet.hold", self.hold, "must be >= 0 s")
        if self.hold is not None and self.hold > 0 and self.force == 0:
            raise invalid("magnet.hold", self.hold, "a static hold needs the magnet's load (magnet.force > 0 N), "
                                                    "or leave it 0 s")

    @property
    def held(self) -> float:
        """Seconds its force rested on the chain before the shot: ``hold``, LONG_HOLD where
        not given (0 where it pulls with no force)."""
        if self.hold is not None:
            return self.hold
        return 0.0 if self.force == 0 else LONG_HOLD

    @classmethod
    def hanging(cls, added_mass: float = 0.0) -> RingMagnet:
        """A ring hanging freely on the bead (plus ``added_mass`` kg): force = weight."""
        return cls(force=(RING_MASS + added_mass) * STANDARD_GRAVITY)

    def force_at(self, position: float) -> float:
        """Pull (N) with the ring centre ``position`` (m) below the bead's centre."""
        z, shape = _pull_profile(RING_INNER, RING_OUTER, RING_THICKNESS)
        return float(self.peak_force * np.interp(position, z, shape))

    def top_force(self):
        """What the chain sees: a constant force (N) or a ForceSchedule."""
        if self.schedule is not None:
            t, f = zip(*self.schedule)
            if min(f) < 0:
                raise invalid("magnet.schedule", self.schedule, "forces must be >= 0 N")
            return ForceSchedule(t, f)
        if self.position is not None:
            return self.force_at(self.position)
        return self.force
