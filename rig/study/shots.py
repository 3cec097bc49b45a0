"""The shots of a study batch as arrays, with no rig built per shot: from the template rig
(rig/study/nominal.py) and each shot's drawn values, the solver's ProblemArrays
(problem_arrays, the function a lone shot's ChainProblem comes from), the instruments'
wiring and the forces and draws they read (instruments/devices/batch.py). This covers studies that
vary only ARRAY_KEYS and the gauges' gains and position errors; any other key changes the
rig's parts, and batch.py builds those shots' rigs.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from instruments.devices.batch import Wiring
from rig.experiment.shot import Rig
from rig.experiment.truth import speeds_between
from rig.model.parts import GaugeBead
from rig.model.statics import contact_constants_of, equilibrium_positions_of, static_forces_of
from rig.solver.problem import PER_BODY, ChainProblem, ProblemArrays, contacts_at_rest, problem_arrays

ARRAY_KEYS = ("striker.velocity", "striker.mass", "chain.bead_mass", "chain.youngs_modulus", "chain.poisson_ratio",
              "magnet.force")
DRAW_FIELDS = ("gain", "misalignment")  # gauges.NAME.FIELD: what replaces a gauge's draw


def array_keys(keys, template: Rig) -> bool:
    """Whether a study varying ``keys`` can take its shots as arrays of ``template``: only
    ARRAY_KEYS and gauge draws, and magnet.force only where the magnet's force is set
    directly (not from its position or a schedule)."""
    magnet = template.magnet
    for key in keys:
        parts = key.split(".")
        if parts[0] == "gauges" and parts[-1] in DRAW_FIELDS:
            continue
        if key not in ARRAY_KEYS:
            return False
        if key == "magnet.force" and (magnet is None or magnet.position is not None or magnet.schedule is not None):
            return False
    return True


@dataclass(frozen=True, eq=False)
class Shots:
    """A batch's shots as arrays: problems (the solver's), possible (shots,): False where
    the values are ones no rig can have (a speed <= 0, a mass <= 0, ...), positions
    (shots, gauges): each gauge bead's equilibrium centre (m), fixed (shots, gauges, 2):
    gain factors and position errors that replace the draws (nan: drawn)."""

    problems: ProblemArrays
    possible: np.ndarray
    positions: np.ndarray
    fixed: np.ndarray

    def take(self, rows) -> Shots:
        """The shots of ``rows`` (indices) alone."""
        p = self.problems
        arrays = {k: getattr(p, k)[rows] for k in PER_BODY + ("load", "energy_scale", "momentum_scale")}
        return Shots(ProblemArrays(p.layout, **arrays), self.possible[rows], self.positions[rows], self.fixed[rows])


def wiring_of(rig: Rig) -> Wiring:
    """The instruments a rig's shot reads, in the order a shot draws them (Rig.fire)."""
    gauges = [(g.channel, g.settings, True) for g in rig.gauges]
    if rig.wall_sensor is not None:
        gauges.append((rig.wall_sensor.channel, rig.wall_sensor.settings, False))
    return Wiring(tuple(gauges), rig.scope)


def shots_of(template: Rig, layout: ChainProblem, values: dict, masses: list) -> Shots:
    """The Shots of ``values`` ({key: (shots,) SI values}) and ``masses`` (per shot: each
    plain bead's mass, kg, or None) on ``template``'s ``layout`` (its ChainProblem)."""
    chain = template.chain
    S = len(masses)
    def col(key, default):
        return np.asarray(values[key], dtype=float) if key in values else np.full(S, default, dtype=float)
    bead_mass = np.tile(chain.masses, (S, 1))
    if any(m is not None for m in masses):
        plain = [j for j, b in enumerate(chain.beads) if b.kind != "magnetic"]
        bead_mass[:, plain] = np.array(masses, dtype=float)
        for g in template.gauges:  # a gauge bead: caps cut from its plain bead, and the plate (GaugeBead)
            bead = chain.beads[g.bead]
            bead_mass[:, g.bead] = GaugeBead.caps_of(bead_mass[:, g.bead]) + bead.plate_mass
    plain_material = next(b.material for b in chain.beads if b.kind != "magnetic")
    E, nu = col("chain.youngs_modulus", plain_material.E), col("chain.poisson_ratio", plain_material.nu)
    top = col("magnet.force", chain.initial_top_force)
    striker = chain.striker
    velocity = col("striker.velocity", striker.velocity if striker else math.nan)
    striker_mass = col("striker.mass", striker.mass if striker else math.nan)
    possible = (np.all(np.isfinite(bead_mass) & (bead_mass > 0), axis=1) & (E > 0) & (nu > -1) & (nu < 0.5)
                & np.isfinite(top) & (top >= 0))
    if striker is not None:
        possible &= (velocity > 0) & (striker_mass > 0) & np.isfinite(velocity) & np.isfinite(striker_mass)
    varied = "chain.youngs_modulus" in values or "chain.poisson_ratio" in values
    A = contact_constants_of(chain, E, nu) if varied else np.tile(chain.contact_constants(), (S, 1))
    bodies = np.append(bead_mass, np.full((S, len(chain.body_masses) - bead_mass.shape[1]),
                                          chain.body_masses[-1]), axis=1)  # a compliant wall's plate
    at_rest = contacts_at_rest(chain, A, static_forces_of(bodies, chain.gravity, top))  # one row where all alike
    arrays = problem_arrays(chain, bead_mass, A, top, striker_mass if striker else None,
                            velocity if striker else None, at_rest)
    # the beads rest where a lone shot's do (Chain.equilibrium_positions): on the overlaps a static hold left
    x = equilibrium_positions_of([b.radius for b in chain.beads], at_rest[1][:, :chain.n_beads + 1])
    beads = [g.bead for g in template.gauges]
    positions = np.repeat(x[:, beads], S // x.shape[0], axis=0)
    fixed = np.full((S, len(wiring_of(template).gauges), 2), np.nan)
    for k, g in enumerate(template.gauges):
        for f, field in enumerate(DRAW_FIELDS):
            fixed[:, k, f] = col(f"gauges.{g.name}.{field}", math.nan)
    return Shots(ProblemArrays(layout, **arrays), possible, positions, fixed)


def wave_speeds(template: Rig, shots: Shots, forces: np.ndarray, h: float) -> np.ndarray:
    """Each shot's leading-pulse speed (m/s; nan where it has none) between its outermost
    gauge beads, from the forces its gauges read ((shots, gauges, samples), the bead gauges
    first, every h s): the speed that turns a position error into a delay (Truth)."""
    order = np.argsort([g.bead for g in template.gauges], kind="stable")
    top, bottom = order[0], order[-1]
    return speeds_between(shots.positions[:, top], shots.positions[:, bottom], forces, int(top), int(bottom), h)
