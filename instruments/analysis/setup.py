"""What the analysis is told of a rig: the gauges (channel, position, sensitivity, RC time
constant) and the chain (bead diameter, beta, F_0), the peak rules and the limits of a
plausible speed. It needs no simulator: what the analysis knows of the physics arrives
here as data."""
from __future__ import annotations

from dataclasses import dataclass, field

from ..errors import InstrumentError, check
from .plausibility import Limits
from .pulse import PeakRules


@dataclass(frozen=True)
class GaugeSetup:
    """A gauge as the analysis knows it: its channel, nominal position (m, down the chain),
    sensitivity (V/N; 1 gives results in volts) and RC time constant (s; None: no inversion)."""

    channel: str
    position_m: float = 0.0
    sensitivity_V_per_N: float = 1.0
    tau_s: float | None = None

    def __post_init__(self):
        check("gauge.sensitivity", self.sensitivity_V_per_N, lo=0, unit="V/N")
        if self.tau_s is not None:
            check("gauge.tau", self.tau_s, lo=0, unit="s")



@dataclass(frozen=True)
class Setup:
    """What the analysis is told: the two gauges (upper first), the wall sensor if any, the
    bead diameter (m), beta = F_d / F_m,e and F_0 (N) from the scene's numerics, the peak
    rules, the distance from the lower gauge to the wall (m) where no wall sensor says
    when the reflection arrives, the limits of a plausible speed, and the unit of the
    forces ("N", or "V" where no sensitivity converts the gauges' volts)."""

    upper: GaugeSetup
    lower: GaugeSetup
    wall: GaugeSetup | None = None
    bead_diameter_m: float = 4.76e-3
    beta: float = 1.0
    static_force_N: float = 0.0
    rules: PeakRules = field(default_factory=PeakRules)
    wall_distance_m: float | None = None
    limits: Limits = field(default_factory=Limits)
    force_unit: str = "N"

    def __post_init__(self):
        distance = self.lower.position_m - self.upper.position_m
        if not distance > 0:
            raise InstrumentError(f"the lower gauge ({self.lower.channel}, {self.lower.position_m:.6g} m) is not "
                                  f"below the upper one ({self.upper.channel}, {self.upper.position_m:.6g} m): "
                                  f"their distance is {distance:.6g} m; allowed > 0 m")
        check("beta", self.beta, lo=0, hi=10)

