"""Extrapolation of an observable to step size h -> 0 (pure numpy), as Coshic & Hummer (arXiv 2603.02383)
do for the O(h^2) bias of second-order integrators.

:func:`extrapolate_h2` fits y(h) = a + b h^2 to the values y_i at step sizes h_i by weighted least squares,
weights 1 / se_i^2 (the points' standard errors).  The errors of a and b are the square roots of the
diagonal of (X^T W X)^-1: they come from the points' errors alone, not rescaled by the fit's scatter; the
reduced chi^2 is reported so that a model that does not fit (chi2_red >> 1: a higher-order term, or
underestimated errors) is visible.  Two points determine the line exactly (no chi^2).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...support.errors import InputError

__all__ = ["H2Fit", "extrapolate_h2"]


@dataclass
class H2Fit:
    """y(h) = a + b h^2: a (the h -> 0 value, the observable's unit), b (its unit per h unit^2), their
    standard errors and covariance, the reduced chi^2 (nan for 2 points) and the degrees of freedom."""

    a: float
    a_se: float
    b: float
    b_se: float
    cov_ab: float
    chi2_red: float
    dof: int

    def at(self, h) -> float:
        """The fitted value a + b h^2."""
        return self.a + self.b * np.asarray(h, dtype=np.float64) ** 2


def extrapolate_h2(h, y, se) -> H2Fit:
    """Weighted least-squares fit y = a + b h^2 of the values ``y`` with standard errors ``se`` (> 0) at step
    sizes ``h`` (any unit, e.g. fs; at least 2 distinct)."""
    h, y, se = (np.atleast_1d(np.asarray(a, dtype=np.float64)) for a in (h, y, se))
    if not (h.shape == y.shape == se.shape and h.ndim == 1):
        raise InputError(f"h, y and se must be 1-D of one length, got shapes {h.shape}, {y.shape}, {se.shape}")
    if not np.all(np.isfinite(y)) or not np.all(np.isfinite(h)):
        raise InputError(f"h and y must be finite, got h={h.tolist()}, y={y.tolist()}")
    if not np.all((se > 0) & np.isfinite(se)):
        raise InputError(f"every standard error must be finite and > 0 (they are the fit's weights), got {se.tolist()}")
    if len(np.unique(h ** 2)) < 2:
        raise InputError(f"the fit needs at least 2 distinct step sizes, got {h.tolist()}")
    X = np.column_stack([np.ones_like(h), h ** 2])
    w = 1.0 / se ** 2
    cov = np.linalg.inv(X.T @ (w[:, None] * X))
    a, b = cov @ (X.T @ (w * y))
    dof = len(h) - 2
    resid = (y - a - b * h ** 2) / se
    chi2_red = float(resid @ resid / dof) if dof > 0 else float("nan")
    return H2Fit(float(a), float(np.sqrt(cov[0, 0])), float(b), float(np.sqrt(cov[1, 1])), float(cov[0, 1]),
                 chi2_red, dof)
