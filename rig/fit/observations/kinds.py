"""What can be observed of a shot: the kinds of observation, each with its SI unit, where it
is measured and how, on the shot's noise-free truth (rig.experiment.truth): a gauge reads
the average of its bead's two contact forces (the rigid gauge bead's plate), the wall
sensor the wall's force, both less their static values (the scope sees the dynamic part).

An Observation is one observed figure with its standard uncertainty, of the shot of a scene
with its overrides; a ratio is the figure of one shot over the same figure of another.
"""
from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from rig.fit.observations import measures

WALL = "wall"
"""The name that places an observation at the wall sensor instead of a gauge."""
ROUND_TRIP = 0.8
"""A gauge's train and tail are looked at until this fraction of the leading pulse's round
trip from the gauge to the wall and back has passed after its peak there: the pulse the
wall reflects rises before its peak comes back, and faster than the incident one."""


@dataclass(frozen=True)
class Shot:
    """One virtual shot an observation needs: a scene (name or file) and its overrides
    (``KEY=VALUE`` texts, applied after the fitted parameters')."""

    scene: str
    overrides: tuple = ()

    def label(self) -> str:
        return self.scene + "".join(f" {o}" for o in self.overrides)


@dataclass(frozen=True)
class Observation:
    """One observed figure: ``kind`` (a name in KINDS), ``value`` and its standard
    uncertainty ``sd`` in the kind's SI unit ``unit``, of ``shot``, at ``gauge`` (a gauge's
    name in the scene, or "wall"; "" for a speed or the wall's peak). A ratio also has
    ``of`` (the kind whose figures it divides) and ``over`` (the shot of its denominator,
    at the same gauge). ``label``: where it was read (file and entry), for messages.
    ``limit``: "" for a measured value; "at least" or "at most" where the observation says
    only that the figure is at least or at most ``value`` (a train "seen"): a model's figure
    on the allowed side then costs nothing, one beyond it (figure - value) / sd (LIMITS)."""

    kind: str
    value: float
    sd: float
    unit: str
    shot: Shot
    gauge: str = ""
    of: str = ""
    over: Shot | None = None
    limit: str = ""
    label: str = ""

    def shots(self) -> tuple:
        return (self.shot,) if self.over is None else (self.shot, self.over)


LIMITS = {"at least": (-math.inf, 0.0), "at most": (0.0, math.inf)}
"""The one-sided observations: the range of (figure - value) / sd that counts as one
standard deviation's residual; on the allowed side the residual is 0."""


def signal(truth, where: str) -> tuple[np.ndarray, np.ndarray]:
    """(t, f) of a truth at a gauge or the wall: times from the impact (s) and the dynamic
    force (N, less its value before the impact)."""
    f = truth.wall_force if where == WALL else truth.gauges[where].average_force
    f = np.asarray(f, dtype=float)
    return np.arange(f.size) * truth.sample_interval, f - f[0]


def look_until(truth, where: str) -> float:
    """Until when (s from the impact) a gauge's train and tail are its own: ROUND_TRIP of the
    leading pulse's way from the gauge to the wall and back after its peak at the gauge
    (inf at the wall, or where the shot has no wall sensor or no pulse)."""
    if where == WALL or truth.wall_force is None:
        return math.inf
    here, wall = measures.leading_pulse(*signal(truth, where)), measures.leading_pulse(*signal(truth, WALL))
    if here is None or wall is None or not wall.time > here.time:
        return math.inf
    return here.time + ROUND_TRIP * 2.0 * (wall.time - here.time)


def _speed(truth, where: str) -> float:
    g = sorted(truth.gauges.values(), key=lambda x: x.position_m)
    if len(g) < 2:
        return math.nan
    h = truth.sample_interval
    t = np.arange(g[0].average_force.size) * h
    return measures.pulse_speed(t, g[0].average_force - g[0].average_force[0],
                                g[-1].average_force - g[-1].average_force[0], g[-1].position_m - g[0].position_m)


@dataclass(frozen=True)
class Kind:
    """An observation kind: its SI unit, whether it is taken at a gauge (or the wall), and
    its measurement on a truth at a place (``measure(truth, where)``)."""

    unit: str
    at_gauge: bool
    measure: Callable | None  # None: a ratio, measured by ``measure`` from two shots
    meaning: str


KINDS = {
    "speed": Kind("m/s", False, _speed,
                  "the leading pulse's speed between the scene's outermost gauges (peak to peak)"),
    "peak": Kind("N", True, lambda tr, w: measures.peak(*signal(tr, w)),
                 "the leading pulse's peak of the gauge reading (or the wall's force)"),
    "fwhm": Kind("s", True, lambda tr, w: measures.fwhm(*signal(tr, w)),
                 "the leading pulse's full width at half maximum"),
    "duration": Kind("s", True, lambda tr, w: measures.full_duration(*signal(tr, w)),
                     "the leading pulse's full duration: its 10% rise to the earlier of its 10% fall "
                     "and its first real dip (a minimum the signal rises 5% of the amplitude from)"),
    "top_fraction": Kind("1", True, lambda tr, w: measures.top_fraction(*signal(tr, w)),
                         "the leading pulse's time above 90% of its amplitude over its FWHM: about 0.4 for a "
                         "bell-shaped pulse, above 0.6 a flat-topped or shock-like one"),
    "pulses": Kind("1", True, lambda tr, w: measures.pulses_in_train(*signal(tr, w), until=look_until(tr, w)),
                   "the number of pulses in the train (above 10% of the leading one, apart where the "
                   "signal falls below half the smaller)"),
    "wall_peak": Kind("N", False, lambda tr, w: measures.peak(*signal(tr, WALL)),
                      "the wall's peak force (its leading pulse)"),
    "tail": Kind("1", True, lambda tr, w: measures.tail_excursion(*signal(tr, w), until=look_until(tr, w)),
                 "the oscillating tail after the leading pulse (from 1.5 FWHM after its peak, 400 us): half "
                 "its peak-to-peak excursion about its slow part (a running mean over the tail's own period, "
                 "its curvature bias removed), over the leading pulse's peak"),
    "ratio": Kind("1", True, None, "a figure (of = KIND) of one shot over the same figure of another (over_scene, "
                                   "over_set), at the same gauge"),
}
"""The observation kinds by name."""


def measure(obs: Observation, truths: dict) -> float:
    """The model's value of ``obs`` (SI) from the truths of its shots ({Shot: Truth or
    None}); nan where a shot is missing (refused or blew up) or the figure is undefined."""
    if any(truths.get(s) is None for s in obs.shots()):
        return math.nan
    if obs.kind == "ratio":
        inner = KINDS[obs.of].measure
        assert inner is not None, "a ratio is of a measured kind (reading.py refuses a ratio of ratios)"
        num, den = inner(truths[obs.shot], obs.gauge), inner(truths[obs.over], obs.gauge)
        return num / den if den != 0 else math.nan
    own = KINDS[obs.kind].measure
    assert own is not None, "only a ratio has no measure of its own"
    return float(own(truths[obs.shot], obs.gauge))
