"""ChainProblem: a Chain flattened into the arrays the kernels integrate (what is simulated;
what is recorded is the SaveAt given to ``solve``). ``problem_arrays`` computes those
arrays for many shots of one chain layout at once, shots first; a ChainProblem is its one
row, so a shot of a study has the bits it has alone."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rig.model.chain import Chain, ForceSchedule
from rig.model.contact import HERTZ, KUWABARA_KONO, PLASTIC, POWER
from rig.model.laws.thornton import STATE_ROWS
from rig.model.statics import static_forces_of
from rig.solver.rest import balance_at_rest

CONTACT_ROWS = ("expo", "damping", "dashpot", "dashpot_exponent", "yield_rate_exponent", "yield_reference_rate")
"""The rows of the kernels' ``con`` array, each slot's law: exponent n, Kuwabara-Kono damping
time tau (s), dashpot coefficient gamma (N (s/m)^alpha), dashpot exponent alpha, and the
yield's rate exponent m and reference rate r_ref (m/s) (rig.model.laws.thornton)."""
PER_BODY = ("mass", "invm", "bias", "A", "d0", "f0", "d_limit", "drag", "friction", "u0", "v0") + CONTACT_ROWS \
    + STATE_ROWS
"""A ChainProblem's arrays of one value per body (or per contact slot): STATE_ROWS are each
slot's memory before the shot (rig.model.laws.thornton), which the kernels copy and renew."""


def kernel_law(expo, damping, dashpot, yield_overlap=None) -> int:
    """The kernels' code for contacts of exponents ``expo``, damping times, dashpots and
    reference yield overlaps (arrays of the live slots): PLASTIC where any contact yields,
    else HERTZ, KUWABARA_KONO (Hertz with viscous terms) or POWER."""
    if yield_overlap is not None and np.any(yield_overlap > 0):
        return PLASTIC
    if np.all(expo == 1.5):
        return HERTZ if not (np.any(damping) or np.any(dashpot)) else KUWABARA_KONO
    return POWER


@dataclass(frozen=True, eq=False, kw_only=True)
class _BodyArrays:
    """The arrays a ChainProblem (one per body, or per contact slot) and ProblemArrays (the
    same with a leading shot axis) share, named as in PER_BODY (and ``load``, one longer),
    and what the kernels read off them (ChainProblem's doc says each array's unit)."""

    mass: np.ndarray
    invm: np.ndarray
    bias: np.ndarray
    load: np.ndarray
    A: np.ndarray
    expo: np.ndarray
    d0: np.ndarray
    f0: np.ndarray
    damping: np.ndarray
    dashpot: np.ndarray
    dashpot_exponent: np.ndarray
    yield_rate_exponent: np.ndarray
    yield_reference_rate: np.ndarray
    permanent_overlap: np.ndarray
    unloading_constant: np.ndarray
    largest_rate: np.ndarray
    yield_overlap: np.ndarray
    plastic_work: np.ndarray
    reference_yield_overlap: np.ndarray
    elastic_limit: np.ndarray
    last_overlap: np.ndarray
    last_rate: np.ndarray
    shifted_rest_overlap: np.ndarray
    d_limit: np.ndarray
    drag: np.ndarray
    friction: np.ndarray
    u0: np.ndarray
    v0: np.ndarray

    @property
    def law(self) -> int:
        """The kernels' contact code of the live slots (of every shot together; kernel_law)."""
        live = self.A > 0
        return kernel_law(self.expo[live], self.damping[live], self.dashpot[live],
                          self.reference_yield_overlap[live])

    @property
    def onsite(self) -> bool:
        """Whether the holder drags or rubs any bead."""
        return bool(np.any(self.drag) or np.any(self.friction))


@dataclass(frozen=True, eq=False)
class ProblemArrays(_BodyArrays):
    """Many shots of one chain layout: the ChainProblem arrays with a leading shot axis
    (``load`` (shots, bodies + 1), the others (shots, bodies)), energy_scale and
    momentum_scale (shots,); ``layout``: a ChainProblem of the layout (its offset, wall
    slot, law and schedule, which every shot shares)."""

    layout: ChainProblem
    energy_scale: np.ndarray
    momentum_scale: np.ndarray

    @property
    def shots(self) -> int:
        return self.mass.shape[0]

    @property
    def offset(self) -> int:
        return self.layout.offset

    @classmethod
    def of(cls, problems: list) -> ProblemArrays:
        """The problems' arrays stacked (one layout)."""
        stack = {k: np.stack([getattr(p, k) for p in problems]) for k in PER_BODY + ("load",)}
        return cls(problems[0], **stack, energy_scale=np.array([p.energy_scale for p in problems]),
                   momentum_scale=np.array([p.momentum_scale for p in problems]))


def contacts_at_rest(chain: Chain, A_c: np.ndarray, F_c: np.ndarray) -> tuple:
    """(state, d0): Chain.contact_memory of shots' contacts of constants A_c (N/m^n) carrying
    static forces F_c (N) ((shots, contacts) each): the kernels' memory of each contact
    (STATE_ROWS first) and the static overlaps (m) a static hold left. Where every shot
    has the same contacts (a study that varies the striker) of one row (shots axis 1),
    the chain's own (computed once) where they are the chain's."""
    if not (_rows_alike(A_c) and _rows_alike(F_c)):
        return chain.contact_memory(A_c, F_c)[:2]
    if np.array_equal(A_c[0], chain.contact_constants(), equal_nan=True) and np.array_equal(F_c[0],
                                                                                            chain.static_forces()):
        return chain.rest_state()[:, None], chain.static_overlaps()[None]
    return chain.contact_memory(A_c[:1], F_c[:1])[:2]


def problem_arrays(chain: Chain, masses, A_c, top_force, striker_mass=None, velocity=None,
                   at_rest: tuple | None = None) -> dict:
    """The kernels' arrays of shots of ``chain``'s layout that differ in their bead masses
    (kg, (shots, beads)), contact constants (N/m^n, (shots, contacts), nan where no
    partner), initial top force (N, (shots,)), and striker mass (kg) and velocity (m/s)
    ((shots,); None: the chain's): {name: array, shots first} (ChainProblem's fields).
    The contacts' exponents and dissipation, the holder's drag and friction and a
    compliant wall's plate are the chain's. at_rest: contacts_at_rest of these shots,
    where the caller has it."""
    masses, A_c = np.atleast_2d(masses), np.atleast_2d(A_c)
    top = np.asarray(top_force, dtype=float).reshape(-1)
    S, n = masses.shape
    off = 1 if chain.striker is not None else 0
    plate_mass = None if chain.wall is None else chain.wall.plate_mass  # None: no wall, or a rigid one
    plate = plate_mass is not None
    nb = off + n + (1 if chain.wall is not None else 0) + (1 if plate else 0)
    bodies = np.concatenate((masses, np.full((S, 1), plate_mass)), axis=1) if plate else masses
    mass = np.zeros((S, nb))
    mass[:, off:off + bodies.shape[1]] = bodies
    if chain.striker is not None:
        striker_mass = np.full(S, chain.striker.mass) if striker_mass is None else np.asarray(striker_mass, float)
        velocity = np.full(S, chain.striker.velocity) if velocity is None else np.asarray(velocity, float)
        mass[:, 0] = striker_mass
    invm = np.divide(1.0, mass, out=np.zeros_like(mass), where=mass > 0)
    bias = np.where(mass > 0, chain.gravity, 0.0)
    bias[:, off] += top / mass[:, off]
    load = np.zeros((S, nb + 1))
    load[:, 1:] = np.cumsum(mass * bias, axis=1)

    expo_c = chain.contact_exponents()
    F_c = static_forces_of(bodies, chain.gravity, top)
    state_c, d_c = contacts_at_rest(chain, A_c, F_c) if at_rest is None else at_rest
    state = np.zeros((len(STATE_ROWS), S, nb))
    state[STATE_ROWS.index("elastic_limit")] = np.inf  # a slot of no contact never yields
    A, d0, f0 = np.zeros((S, nb)), np.zeros((S, nb)), np.zeros((S, nb))
    expo, damping, dashpot = np.full((S, nb), 1.5), np.zeros((S, nb)), np.zeros((S, nb))
    dashpot_exponent = np.ones((S, nb))
    d_limit = np.full((S, nb), math.inf)
    radii = np.array([b.radius for b in chain.beads])
    near = np.minimum(np.append(math.inf, radii), np.append(radii, math.inf))  # contact k: beads k-1, k
    near = np.append(near, math.inf) if plate else near  # the rod: no overlap limit of its own
    slot = np.arange(chain.n_contacts) + off
    live = np.isfinite(chain.contact_constants()) & (slot > 0) & (slot < nb)
    to, at = _span(slot[live]), _span(np.flatnonzero(live))  # each live contact's slot, and the contact
    A[:, to], d0[:, to], f0[:, to] = A_c[:, at], d_c[:, at], F_c[:, at]
    expo[:, to] = expo_c[at]
    tau_c, gamma_c, alpha_c = chain.contact_dissipation()
    damping[:, to], dashpot[:, to] = tau_c[at], gamma_c[at]
    dashpot_exponent[:, to] = alpha_c[at]
    state[:, :, to] = state_c[:, :, at]
    m_c, r_c = chain.contact_yield_rates()
    yield_rate_exponent, yield_reference_rate = np.zeros((S, nb)), np.ones((S, nb))
    yield_rate_exponent[:, to], yield_reference_rate[:, to] = m_c[at], r_c[at]
    d_limit[:, to] = 0.5 * near[at]
    if chain.striker is not None:
        d0[:, 1] = -chain.striker.gap
    balance_at_rest(load, A, d0, expo, invm)  # before d_limit, f0, e_scale read d0
    state[STATE_ROWS.index("shifted_rest_overlap")] = d0 - state[STATE_ROWS.index("permanent_overlap")]
    beads = np.zeros((S, nb), dtype=bool)
    beads[:, off:off + n] = True  # the holder drags and rubs the beads only
    drag = np.where(beads, chain.drag * invm, 0.0)
    friction = np.where(beads, chain.friction * invm, 0.0)
    u0, v0 = np.zeros((S, nb)), np.zeros((S, nb))
    if off:
        v0[:, 0] = velocity
        e_scale, p_scale = 0.5 * striker_mass * velocity**2, striker_mass * velocity
    else:  # no impact: the static elastic energy and its momentum scale
        e_scale = np.sum(np.where(expo == 1.5, 0.4 * f0 * d0, f0 * d0 / (expo + 1.0)), axis=1)
        e_scale = np.where(e_scale == 0.0, 1.0, e_scale)
        p_scale = np.sqrt(2.0 * mass.sum(axis=1) * e_scale)
    return dict(mass=mass, invm=invm, bias=bias, load=load, A=A, expo=expo, d0=d0, f0=f0, damping=damping,
                dashpot=dashpot, dashpot_exponent=dashpot_exponent, yield_rate_exponent=yield_rate_exponent,
                yield_reference_rate=yield_reference_rate, **dict(zip(STATE_ROWS, state)), d_limit=d_limit,
                drag=drag, friction=friction, u0=u0, v0=v0, energy_scale=e_scale, momentum_scale=p_scale)


def _span(index: np.ndarray):
    """``index`` (ascending) as a slice where it is a run of consecutive indices (numpy
    reads and writes a slice faster than an index array), else as it is."""
    return slice(int(index[0]), int(index[-1]) + 1) if index.size and np.all(np.diff(index) == 1) else index


def _rows_alike(a: np.ndarray) -> bool:
    """Whether every row of ``a`` (shots, ...) holds the first row's numbers (nan for nan)."""
    return bool(np.all((a == a[0]) | (np.isnan(a) & np.isnan(a[0]))))


@dataclass(frozen=True, eq=False)
class ChainProblem(_BodyArrays):
    """Bodies from the top: [striker] + beads + [wall as a body of zero inverse mass].

    Arrays are per body (size nb) in SI: mass (kg; 0 for the wall), invm (1/kg), bias
    (constant acceleration, m/s^2: gravity, plus top force / m on bead 0), load (size nb+1:
    the constant force carried from above through each slot, N), drag (1/s) and friction
    (m/s^2): the holder's drag and Coulomb friction over the body's mass; and per contact
    slot (slot i joins bodies i-1 and i): A (N/m^n), expo (n), d0 (m), f0 (N), damping (s,
    Kuwabara-Kono), dashpot (gamma, N (s/m)^alpha: kg/s for a linear one), dashpot_exponent
    (alpha, 1: linear), yield_rate_exponent and yield_reference_rate (m/s) of a yielding
    contact, its memory before the shot (STATE_ROWS: permanent_overlap (m),
    unloading_constant (N/m^n, A where as new), largest_rate (m/s), yield_overlap (m),
    plastic_work (J), reference_yield_overlap (m; 0: it never yields), elastic_limit (m; inf: it
    never yields), last_overlap (m), last_rate (m/s), shifted_rest_overlap (m, d0 - delta_p);
    rig.model.laws.thornton),
    d_limit (m, an overlap beyond which the integration is declared unstable). u0, v0 the
    initial state (m, m/s). With a compliant wall the plate
    is a body and the rod the slot below it, to the wall's immovable body.
    """

    chain: Chain
    offset: int
    sched_body: int
    sched_t: np.ndarray
    sched_f: np.ndarray
    wall_slot: int
    energy_scale: float
    momentum_scale: float

    @classmethod
    def from_chain(cls, chain: Chain) -> ChainProblem:
        a = problem_arrays(chain, chain.masses, chain.contact_constants(), chain.initial_top_force)
        off = 1 if chain.striker is not None else 0
        nb = a["mass"].shape[1]
        if isinstance(chain.top_force, ForceSchedule):
            sched_t = np.array(chain.top_force.times)
            sched_f = np.array(chain.top_force.forces) - chain.initial_top_force
        else:
            sched_t = np.zeros(0)
            sched_f = np.zeros(0)
        return cls(chain, off, **{k: a[k][0] for k in PER_BODY + ("load",)}, sched_body=off, sched_t=sched_t,
                   sched_f=sched_f, wall_slot=nb - 1 if chain.wall is not None else 0,
                   energy_scale=float(a["energy_scale"][0]), momentum_scale=float(a["momentum_scale"][0]))

    @property
    def n_bodies(self) -> int:
        return self.mass.shape[0]

    def memory(self) -> np.ndarray:
        """A fresh copy of the contacts' memory before the shot (STATE_ROWS, bodies): the
        kernels' ``state``, which they renew in place."""
        return np.stack([getattr(self, k) for k in STATE_ROWS])

    @property
    def slip_speed(self) -> float:
        return self.chain.slip_speed

    @property
    def moving_bodies(self) -> int:
        return int(np.count_nonzero(self.invm))
