"""How the parts of a scene are wired and solved: small frozen records that cross module
boundaries instead of tuples and dicts."""
from __future__ import annotations

import math
from dataclasses import dataclass

from instruments.devices.gauges import GaugeSettings
from rig.errors import invalid
from rig.solver.methods import method
from rig.solver.stepsize import checked_accuracy


@dataclass(frozen=True)
class GaugeWiring:
    """A gauge bead: its name in the scene, its chain index (0 = top bead, the magnetic
    bead included), the scope channel it is wired to, its signal chain's settings and its
    mass (kg; None: caps cut from a plain bead plus the plate, rig.model.parts.GaugeBead)."""

    name: str
    bead: int
    channel: str
    settings: GaugeSettings
    mass: float | None = None


@dataclass(frozen=True)
class WallWiring:
    """The wall sensor: the scope channel it is wired to and its signal chain's settings."""

    channel: str
    settings: GaugeSettings


@dataclass(frozen=True)
class SolverSettings:
    """The [solver] table: method name, accuracy target (None: the method's default),
    simulated duration (s) and the output grid's sample interval (s)."""

    method: str = "srkn6b"
    accuracy: float | None = None
    duration: float = math.nan  # required: __post_init__ refuses a missing one
    sample_interval: float = 1e-7

    def __post_init__(self):
        d = self.duration
        if d is None or not (isinstance(d, (int, float)) and math.isfinite(d) and d > 0):
            raise invalid("solver.duration", d, "simulated time > 0 s, e.g. '4 ms'")
        method(self.method)
        h = self.sample_interval
        if not (isinstance(h, (int, float)) and 0 < h < math.inf):
            raise invalid("solver.sample_interval", h, "the output grid's interval, > 0 s, e.g. '0.1 us'")
        if not h < d:
            raise invalid("solver.sample_interval", f"{h:g} s", f"shorter than solver.duration = {d:g} s")
        if self.accuracy is not None:
            checked_accuracy(self.accuracy, "solver.accuracy")

    @classmethod
    def from_table(cls, table: dict) -> SolverSettings:
        duration = table.get("duration")  # None (missing): refused by __post_init__, naming the key
        return cls(table.get("method", "srkn6b"), table.get("accuracy"), duration,  # type: ignore[arg-type]
                   table.get("sample_interval", 1e-7))
