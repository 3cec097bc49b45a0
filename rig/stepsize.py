"""Choosing the time step: contact time scale, accuracy target, stability limit.

Contact time scale (Nesterenko 2001; the duration of a Hertz collision scales with it):

    tau = min over contacts of  (m / (A v^(1/2)))^(2/5)     impact at speed v
                        and     sqrt(m / k0),  k0 = (3/2) A^(2/3) F0^(1/3)   precompressed

with m the reduced mass of the two bodies. A pulse that crosses N contacts accumulates a
phase error ~ N (dt/tau)^p, so for a target relative force error ``accuracy``

    dt = tau * (accuracy / (C N))^(1/p)

with the method's contact order p and error constant C (calibrated on the solver
benchmark, see docs/solver.md). The step is also kept below half the linear stability
limit omega_max dt < S (S from the method's coefficients), with omega_max bounded by
Gershgorin's theorem on the chain linearised at an upper estimate of the peak forces.
"""
from __future__ import annotations

import math

import numpy as np

from .contact import contact_stiffness
from .methods import Method

DEFAULT_ACCURACY = 1e-4


def _reduced_masses(p) -> np.ndarray:
    """Reduced mass (kg) of each contact slot's two bodies (the wall is infinitely heavy)."""
    out = np.full(p.n_bodies, np.nan)
    out[1:] = 1.0 / (p.invm[:-1] + p.invm[1:])
    return out


def contact_time_scale(p) -> float:
    """tau (s): the shortest contact time scale of the chain (formula in the module doc)."""
    m = _reduced_masses(p)
    live = p.A > 0
    taus = []
    v = float(p.v0.max(initial=0.0))
    if v > 0:
        taus.append(np.min((m[live] / (p.A[live] * math.sqrt(v))) ** 0.4))
    loaded = live & (p.f0 > 0)
    if loaded.any():
        taus.append(np.min(np.sqrt(m[loaded] / contact_stiffness(p.A[loaded], p.f0[loaded]))))
    return float(min(taus)) if taus else math.inf


def peak_force_estimate(p) -> np.ndarray:
    """Upper estimate of each contact's peak force (N): static force plus twice the peak of
    the striker hitting an immovable sphere, F = A (5 m_s v^2 / (4 A))^(3/5)."""
    F = p.f0.copy()
    if p.offset and p.v0[0] > 0:
        A0 = p.A[1]
        hit = A0 * (5.0 * p.mass[0] * p.v0[0] ** 2 / (4.0 * A0)) ** 0.6
        F = F + 2.0 * hit
    return F


def max_frequency(p) -> float:
    """Gershgorin bound (rad/s) on the highest linear frequency at the peak-force estimate."""
    k = np.where(p.A > 0, contact_stiffness(p.A, peak_force_estimate(p)), 0.0)
    k_above = k
    k_below = np.append(k[1:], 0.0)
    im = p.invm
    im_above = np.append(0.0, im[:-1])
    im_below = np.append(im[1:], 0.0)
    rows = im * (k_above + k_below) + k_above * np.sqrt(im * im_above) + k_below * np.sqrt(im * im_below)
    return float(math.sqrt(rows.max())) if rows.max() > 0 else 0.0


def stability_limit(p, method: Method) -> float:
    """Largest stable step (s) for this chain and method (inf if nothing is loaded)."""
    w = max_frequency(p)
    return method.stability / w if w > 0 else math.inf


def accuracy_step(p, method: Method, accuracy: float) -> float:
    """Step (s) meeting ``accuracy`` over a pulse crossing every moving body."""
    tau = contact_time_scale(p)
    return tau * (accuracy / (method.error_constant * max(p.moving_bodies, 1))) ** (1.0 / method.contact_order)


def default_step(p, method: Method, accuracy: float, limit: float | None = None) -> float:
    """The step (s) a solve takes by itself: the accuracy step, at most half the stability
    limit (``limit``, computed here when not given)."""
    limit = stability_limit(p, method) if limit is None else limit
    return min(accuracy_step(p, method, accuracy), 0.5 * limit)
