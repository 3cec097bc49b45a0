"""The noise-free ground truth of a shot: what each gauge bead and the wall felt, from the
solver's recorded forces, and the leading pulse's speed between the outermost gauges."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from instruments.analysis import first_peak_times
from rig.errors import RigError


@dataclass(frozen=True, eq=False)
class GaugeTruth:
    """Noise-free truth at one gauge bead (chain index ``bead``, 0 = top bead)."""

    bead: int
    channel: str
    position_m: float          # equilibrium centre, down from bead 0's centre
    average_force: np.ndarray  # N, what the rigid gauge bead's plate feels
    contact_above: np.ndarray | None  # N (None where only the average was recorded)
    contact_below: np.ndarray | None  # N
    static_above_N: float
    static_below_N: float


@dataclass(frozen=True, eq=False)
class Truth:
    """Ground truth on the solver's output grid t = n * sample_interval (s, 0 = impact)."""

    sample_interval: float
    gauges: dict
    wall_force: np.ndarray | None
    wave_speed_m_per_s: float | None

    def wall(self) -> np.ndarray:
        """The wall sensor's force (N); RigError where the scene has no wall sensor."""
        if self.wall_force is None:
            raise RigError("the scene has no [wall_sensor]: no wall force was recorded")
        return self.wall_force


def truth_of(assembly, solution) -> Truth:
    """The Truth of an assembly's solution (recorded with its ``save_at``: each gauge's two
    contacts "contact{k}" and/or its average "gauge_{name}", and the "wall")."""
    x = assembly.chain.equilibrium_positions()
    F0 = assembly.chain.static_forces()
    gauges = {}
    for g in assembly.gauges:
        j = g.bead
        above, below = solution.forces.get(f"contact{j}"), solution.forces.get(f"contact{j + 1}")
        average = solution.forces.get(f"gauge_{g.name}")
        gauges[g.name] = GaugeTruth(j, g.channel, float(x[j]), 0.5 * (above + below) if average is None else average,
                                    above, below, float(F0[j]), float(F0[j + 1]))
    h = solution.sample_interval
    return Truth(h, gauges, solution.forces.get("wall"), wave_speed(gauges, h))


def wave_speed(gauges: dict, h: float) -> float | None:
    """Leading-pulse speed (m/s) between the outermost gauges, from the truth's peaks."""
    if len(gauges) < 2:
        return None
    g = sorted(gauges.values(), key=lambda t: t.position_m)
    v = speeds_between(np.array([g[0].position_m]), np.array([g[-1].position_m]),
                       np.stack([g[0].average_force, g[-1].average_force])[None], 0, 1, h)[0]
    return None if np.isnan(v) else float(v)


def speeds_between(x_top: np.ndarray, x_bottom: np.ndarray, forces: np.ndarray, top: int, bottom: int,
                   h: float) -> np.ndarray:
    """Each shot's leading-pulse speed (m/s) between two beads at x_top and x_bottom (m, one
    per shot), from the first peaks of their forces, rows ``top`` and ``bottom`` of forces
    (shots, rows, samples; N, every h s): (x_bottom - x_top) / (t_bottom - t_top); nan where
    either has no peak or they come in the wrong order."""
    t = first_peak_times(forces, [top, bottom], h)
    later = t[:, 1] > t[:, 0]  # False where either is nan
    return np.where(later, (x_bottom - x_top) / np.where(later, t[:, 1] - t[:, 0], 1.0), np.nan)
