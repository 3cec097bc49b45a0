"""Registry of integration methods: symmetric kick-drift compositions.

``order`` is the classical order on smooth forces. ``contact_order`` is what the method
achieves on chains whose contacts open and close: the Hertz force d^(3/2) has a second
derivative that is infinite at d = 0, which caps the order of high-order compositions
(measured in tests/solver/test_convergence.py and in the solver benchmark).
``error_constant`` and ``contact_order`` set the automatic step (rig/solver/stepsize.py).
"""
from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from rig.errors import lookup


@dataclass(frozen=True)
class Method:
    name: str
    drifts: tuple   # a_s, sum 1
    kicks: tuple    # b_s, sum 1, one more than drifts (FSAL)
    order: int
    contact_order: float
    error_constant: float
    reference: str

    @property
    def force_evaluations(self) -> int:
        """Force evaluations per step (the last kick's forces are reused by the next step)."""
        return len(self.drifts)

    @property
    def stability(self) -> float:
        """Largest omega*dt for which the method is stable on x'' = -omega^2 x."""
        return harmonic_stability_limit(self.drifts, self.kicks)


@functools.cache
def harmonic_stability_limit(drifts: tuple, kicks: tuple, z_max: float = 20.0) -> float:
    """First z = omega*dt where the one-step matrix of x'' = -omega^2 x has |trace| >= 2."""
    z = np.linspace(1e-6, z_max, 200001)
    m11, m12, m21, m22 = np.ones_like(z), np.zeros_like(z), np.zeros_like(z), np.ones_like(z)

    def kick(b, m11, m12, m21, m22):  # v -= b z^2 x  (h = 1, omega = z)
        return m11, m12, m21 - b * z**2 * m11, m22 - b * z**2 * m12

    for a, b in zip(drifts, kicks[:-1]):
        m11, m12, m21, m22 = kick(b, m11, m12, m21, m22)
        m11, m12 = m11 + a * m21, m12 + a * m22  # x += a v
    m11, m12, m21, m22 = kick(kicks[-1], m11, m12, m21, m22)
    unstable = np.abs(m11 + m22) >= 2.0
    return float(z[np.argmax(unstable)]) if unstable.any() else z_max


def _srkn6b() -> tuple[tuple, tuple]:
    # Blanes & Moan, J. Comput. Appl. Math. 142, 313 (2002), Table 3, SRKN_6^b (order 4).
    b1, b2, b3 = 0.0829844064174052, 0.396309801498368, -0.0390563049223486
    a1, a2 = 0.245298957184271, 0.604872665711080
    a3, b4 = 0.5 - (a1 + a2), 1.0 - 2.0 * (b1 + b2 + b3)
    return (a1, a2, a3, a3, a2, a1), (b1, b2, b3, b4, b3, b2, b1)


METHODS: dict[str, Method] = {
    "verlet": Method("verlet", (1.0,), (0.5, 0.5), order=2, contact_order=2.0,
                     error_constant=0.018, reference="velocity Verlet (Stormer-Verlet)"),
    "srkn6b": Method("srkn6b", *_srkn6b(), order=4, contact_order=2.5,
                     error_constant=2e-6,
                     reference="Blanes & Moan 2002, SRKN_6^b, 6 force evaluations per step"),
}

DEFAULT_METHOD = "srkn6b"


def method(name) -> Method:
    """Look a method up by name."""
    return lookup(METHODS, name, "method", Method)
