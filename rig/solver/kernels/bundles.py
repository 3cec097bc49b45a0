"""What the entry kernels take, by name: named tuples of the arrays and numbers that travel
together (numba types each as a tuple of its fields; an entry kernel reads them into
locals at its top, and the inner loops take flat arrays, as a tuple handed to an inlined
helper costs reference counts in its loop: step.py).

Arrays are the single-shot kernel's (integrators.integrate): per body (nb,) or per slot
(nb + 1,); the batched kernel's (ensemble.integrate_ensemble) carry a leading chunk axis
and the chunk's shots innermost, (chunks, ..., width). Built by rig.solver.run.kernel_inputs.
"""
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

if TYPE_CHECKING:
    from numerics.dispatcher import Constant


class ChainArrays(NamedTuple):
    """The chain: body masses (kg), their inverses (1/kg; 0 for an immovable wall), each
    body's constant force (N, positive down: bias), the constant force carried through each
    slot (N, size nb + 1: load), each slot's contact stiffness A (N/m^n), its static
    overlap d0 (m) and the overlap at which a solve is unstable (m: d_limit)."""

    mass: np.ndarray
    invm: np.ndarray
    bias: np.ndarray
    load: np.ndarray
    A: np.ndarray
    d0: np.ndarray
    d_limit: np.ndarray


class Contacts(NamedTuple):
    """The contacts' law: its kernel code (rig.model.contact: HERTZ, KUWABARA_KONO, POWER,
    PLASTIC), ``con`` each slot's law parameters (rig.solver.problem.CONTACT_ROWS: exponent,
    damping time s, dashpot coefficient and exponent, yield rate exponent, reference rate
    m/s) and ``state`` each slot's memory (rig.model.laws.thornton.STATE_ROWS), which the
    kernels renew in place (PLASTIC only). run.kernel_inputs hands the code as an
    numerics.dispatcher.Constant: every kernel is compiled for the law it runs, the other
    laws' code never compiled."""

    law: "int | Constant"
    con: np.ndarray
    state: np.ndarray


class Holder(NamedTuple):
    """The holder and the contacts' viscous flow: ``onsite`` each body's drag rate (1/s)
    and friction deceleration (m/s^2), friction smoothed over ``slip`` (m/s);
    ``viscous_rate`` (1/s) a bound on the contacts' viscous decay rates
    (dissipation.substeps); ``flows`` 1 where any of these flows acts (a contact's damping
    time or dashpot coefficient, a body's drag or friction not 0), else 0: handed as a
    Constant, the kernels of a chain without flows are compiled without the dissipation's
    code (the same bits: it is never run there)."""

    onsite: np.ndarray
    slip: float
    viscous_rate: float
    flows: "int | Constant"


class Method(NamedTuple):
    """The stepping: the composition's drift and kick coefficients (a_coef, b_coef: one more
    kick than drifts), the step dt (s), the steps n_steps, the multirate head's bodies
    (``head``, 0: none), its substeps in each drift (``sub``, int64) and ``multirate``, 1
    where there is a head (head > 0), else 0: handed as a Constant, the kernels of a solve
    without a head are compiled without the head flow's code (multirate.py; the same bits:
    it is never run there)."""

    a_coef: np.ndarray
    b_coef: np.ndarray
    dt: float
    n_steps: int
    head: int
    sub: np.ndarray
    multirate: "int | Constant"


class Schedule(NamedTuple):
    """The ring magnet's force on body ``body``, piecewise linear in time: times ``t`` (s)
    and forces ``f`` (N), held constant outside the table; an empty table: none (single
    shots only: the batched kernel takes constant loads)."""

    body: int
    t: np.ndarray
    f: np.ndarray


class Record(NamedTuple):
    """What is recorded: channel c is the sum over k of ch_weight[c, k] times the force of
    slot ch_slot[c, k], sampled every sample_dt (s) into ``out`` (channels, samples; a
    batch's (shots, channels, samples)); positions of every body every frame_dt (s) into
    ``frames`` (frames, nb; single shots only, (0, nb): none)."""

    ch_slot: np.ndarray
    ch_weight: np.ndarray
    sample_dt: float
    out: np.ndarray
    frame_dt: float
    frames: np.ndarray


class Checks(NamedTuple):
    """The energy and momentum checks, every ``check_every`` steps and at the end: the
    energy (J: e_ref) and momentum (kg m/s: p_ref) the errors are relative to (a batch's:
    one per shot), and the wall's slot (0: no wall), whose impulse the momentum balance
    counts."""

    check_every: int
    e_ref: float | np.ndarray
    p_ref: float | np.ndarray
    wall_slot: int
