"""Fig. 3 of Daraio et al., Phys. Rev. E 73, 026610 (2006) as data: the observed figures of
the 52-bead PTFE chain's two shots (gravity only and the 2.38 N ring magnet), the ranges
("targets") a model must meet to reproduce the figure, and a parameter set that meets them.

OBSERVATIONS are the entries of scenarios/daraio2006_fig3_observations.toml (where each
number comes from is told there), built in memory through the observation reader's checks.
TARGETS are what the text and the figure say, as ranges on figures of virtual shots' noise-free
truths (rig.fit.observations.kinds); a one-sided target has an infinite bound.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

from rig.fit.observations.kinds import Observation, Shot
from rig.fit.observations.reading import observation

GRAVITY, MAGNETIC = "ptfe52_gravity", "ptfe52_magnetic"

PARAMETER_SET = ("chain.youngs_modulus=0.84 GPa", "chain.contact_law=thornton", "chain.yield_force=0.8 N",
                 "chain.contact_damping=0.05 kg/s", "chain.static_yield_ratio=0.6")
"""Scene overrides of both shots that meet every target: an elastic-plastic (Thornton) PTFE
contact with memory, yielding at 0.8 N, a linear dashpot of 0.05 kg/s beside it, and a
static hold (the magnet's 600 s) yielding at 0.6 of the dynamic yield pressure."""

_ENTRIES = (
    {"kind": "speed", "value": "129 m/s", "sd": "13 m/s", "scene": GRAVITY},
    {"kind": "duration", "value": "170 us", "sd": "25 us", "scene": GRAVITY, "gauge": "upper"},
    {"kind": "speed", "value": "222 m/s", "sd": "22 m/s", "scene": MAGNETIC},
    {"kind": "ratio", "of": "peak", "value": 2.0, "sd": 0.25, "scene": MAGNETIC, "over_scene": GRAVITY,
     "gauge": "upper"},
    {"kind": "tail", "value": 0.0, "sd": 0.05, "scene": MAGNETIC, "gauge": "lower"},
    {"kind": "pulses", "value": 2, "sd": 0.5, "limit": "at least", "scene": GRAVITY, "gauge": "lower"},
)


def observations() -> tuple:
    """The Fig. 3 observations (module doc) as checked Observations, SI units."""
    return tuple(observation(e, GRAVITY, Path("."), f"Fig. 3 observation {i + 1}") for i, e in enumerate(_ENTRIES))


@dataclass(frozen=True)
class Target:
    """A range [lo, hi] (SI, the figure's unit; an open side infinite) that the model's
    ``figure`` must fall in to meet Fig. 3. ``figure`` is an Observation used for where and
    how the figure is measured: its value and sd are nan (no observed number)."""

    name: str
    figure: Observation
    lo: float
    hi: float
    meaning: str

    def holds(self, value: float) -> bool:
        """Whether ``value`` meets the target (a missing figure, nan, never does)."""
        return bool(self.lo <= value <= self.hi)


def _figure(kind: str, unit: str, scene: str, gauge: str = "", of: str = "", over: str = "") -> Observation:
    return Observation(kind, math.nan, math.nan, unit, Shot(scene), gauge, of, None if not over else Shot(over),
                       label=f"Fig. 3 target {kind}{' of ' + of if of else ''} {scene} {gauge}".rstrip())


TARGETS = (
    Target("gravity_speed", _figure("speed", "m/s", GRAVITY), 116.0, 142.0,
           "gravity only: the leading pulse's speed between the gauges (m/s), 129 m/s +- 10%"),
    Target("gravity_duration_upper", _figure("duration", "s", GRAVITY, "upper"), 120e-6, 204e-6,
           "gravity only: the leading pulse's full duration at the upper gauge (20th bead, s), about 170 us"),
    Target("gravity_pulses_lower", _figure("pulses", "1", GRAVITY, "lower"), 2.0, math.inf,
           "gravity only: at least 2 pulses above 10% of the leading one at the lower gauge (29th bead)"),
    Target("magnetic_speed", _figure("speed", "m/s", MAGNETIC), 200.0, 244.0,
           "2.38 N magnet: the leading pulse's speed (m/s), 222 m/s +- 10%"),
    Target("peak_ratio_upper", _figure("ratio", "1", MAGNETIC, "upper", "peak", GRAVITY), 1.5, 2.5,
           "the upper gauge's leading peak with the magnet over that without, about 2"),
    Target("wall_peak_ratio", _figure("ratio", "1", MAGNETIC, "", "wall_peak", GRAVITY), 1.0, math.inf,
           "the wall's peak force with the magnet over that without: at least 1"),
    Target("magnetic_tail_lower", _figure("tail", "1", MAGNETIC, "lower"), 0.0, 0.10,
           "2.38 N magnet: the oscillating tail at the lower gauge over the leading pulse: at most 0.10"),
)
"""The Fig. 3 targets (module doc), in the order of the paper's text."""
