"""Held-out prediction of a finished fit without refitting: the linearised leave-one-out
(PRESS, Allen, Technometrics 16, 125 (1974)). With J the Jacobian of the normalised
residuals at the optimum and H = J (J^T J)^-1 J^T its hat matrix, the residual of datum i
predicted by the fit to the others is

    r_(i) = r_i / (1 - h_ii)

exact for a model linear in its parameters, a first-order approximation otherwise (the
parameters' shift when one datum is left out is taken along the Jacobian). The hat matrix
does not depend on how the parameters are scaled.
"""
from __future__ import annotations

import numpy as np


def leverages(jacobian: np.ndarray) -> np.ndarray:
    """h_ii, the diagonal of the hat matrix of ``jacobian`` (data x parameters)."""
    J = np.asarray(jacobian, dtype=float)
    return np.einsum("ij,jk,ik->i", J, np.linalg.pinv(J.T @ J), J)


def held_out_residuals(jacobian: np.ndarray, residuals: np.ndarray) -> np.ndarray:
    """r_i / (1 - h_ii) for every datum (module doc); inf where a datum alone fixes a
    parameter (h_ii = 1: the others cannot predict it)."""
    h = leverages(jacobian)
    with np.errstate(divide="ignore"):
        return np.where(h < 1.0 - 1e-12, np.asarray(residuals) / (1.0 - h), np.inf)
