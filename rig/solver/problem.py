"""ChainProblem: a Chain flattened into the arrays the kernels integrate (what is simulated;
what is recorded is the SaveAt given to ``solve``)."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rig.model.chain import Chain, ForceSchedule


@dataclass(frozen=True, eq=False)
class ChainProblem:
    """Bodies from the top: [striker] + beads + [wall as a body of zero inverse mass].

    Arrays are per body (size nb) in SI: mass (kg; 0 for the wall), invm (1/kg), bias
    (constant acceleration, m/s^2: gravity, plus top force / m on bead 0), load (size nb+1:
    the constant force carried from above through each slot, N), and per contact
    slot (slot i joins bodies i-1 and i): A (N/m^1.5), d0 (m), f0 (N), damping (s), d_limit
    (m, an overlap beyond which the integration is declared unstable). u0, v0 the initial
    state (m, m/s).
    """

    chain: Chain
    offset: int
    mass: np.ndarray
    invm: np.ndarray
    bias: np.ndarray
    load: np.ndarray
    A: np.ndarray
    d0: np.ndarray
    f0: np.ndarray
    damping: np.ndarray
    d_limit: np.ndarray
    u0: np.ndarray
    v0: np.ndarray
    sched_body: int
    sched_t: np.ndarray
    sched_f: np.ndarray
    wall_slot: int
    energy_scale: float
    momentum_scale: float

    @classmethod
    def from_chain(cls, chain: Chain) -> "ChainProblem":
        off = 1 if chain.striker is not None else 0
        n = chain.n_beads
        nb = off + n + (1 if chain.wall is not None else 0)
        mass = np.zeros(nb)
        mass[off:off + n] = chain.masses
        if off:
            mass[0] = chain.striker.mass
        invm = np.zeros(nb)
        invm[mass > 0] = 1.0 / mass[mass > 0]
        bias = np.where(mass > 0, chain.gravity, 0.0)
        bias[off] += chain.initial_top_force / mass[off]
        load = np.concatenate(([0.0], np.cumsum(mass * bias)))

        A_c, F_c, d_c = chain.contact_constants(), chain.static_forces(), chain.static_overlaps()
        A = np.zeros(nb)
        d0 = np.zeros(nb)
        f0 = np.zeros(nb)
        d_limit = np.full(nb, math.inf)
        radii = np.array([b.radius for b in chain.beads])
        near = np.minimum(np.append(math.inf, radii), np.append(radii, math.inf))  # contact k: beads k-1, k
        slot = np.arange(n + 1) + off
        live = np.isfinite(A_c) & (slot > 0) & (slot < nb)
        A[slot[live]], d0[slot[live]], f0[slot[live]] = A_c[live], d_c[live], F_c[live]
        d_limit[slot[live]] = 0.5 * near[live]
        if off:
            d0[1] = -chain.striker.gap
        damping = np.full(nb, chain.damping_time)

        u0 = np.zeros(nb)
        v0 = np.zeros(nb)
        if off:
            v0[0] = chain.striker.velocity

        if isinstance(chain.top_force, ForceSchedule):
            sched_t = np.array(chain.top_force.times)
            sched_f = np.array(chain.top_force.forces) - chain.initial_top_force
        else:
            sched_t = np.zeros(0)
            sched_f = np.zeros(0)

        if off:
            e_scale = 0.5 * chain.striker.mass * chain.striker.velocity**2
            p_scale = chain.striker.mass * chain.striker.velocity
        else:  # no impact: the static elastic energy and its momentum scale
            e_scale = float(np.sum(0.4 * f0 * d0)) or 1.0
            p_scale = math.sqrt(2.0 * mass.sum() * e_scale)
        return cls(chain, off, mass, invm, bias, load, A, d0, f0, damping, d_limit, u0, v0,
                   off, sched_t, sched_f,
                   nb - 1 if chain.wall is not None else 0, e_scale, p_scale)

    @property
    def n_bodies(self) -> int:
        return self.mass.shape[0]

    @property
    def moving_bodies(self) -> int:
        return int(np.count_nonzero(self.invm))
