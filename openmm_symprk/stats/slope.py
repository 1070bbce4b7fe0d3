"""The drift of a quantity (the total energy of an NVE run): the least-squares slope of y(t) and its standard error.

The samples of an MD run are correlated, so the residuals about the line are too: the slope's variance is
s^2 g / Sxx, with s^2 the residuals' variance, Sxx = sum (t - mean t)^2 and g the residuals' statistical
inefficiency (:func:`.timeseries.statistical_inefficiency`).  This holds when the correlation time is short
against the run (the weights t - mean t change little over it); the calibration tests check the coverage of the
error bar on series with a known slope.

:class:`RunningLine` is the same fit updated with O(1) work per sample (running co-moments), for reporters that
give the slope at every report.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .timeseries import statistical_inefficiency
from ..support.errors import InputError

__all__ = ["Drift", "drift", "RunningLine"]


@dataclass(frozen=True)
class Drift:
    slope: float
    se: float  # standard error of the slope, correlated residuals included
    g: float  # statistical inefficiency of the residuals
    n: int

    @property
    def n_eff(self) -> float:
        """Effectively independent samples, n / g.  The error bar covers the true slope at its stated rate when
        this is large (95% for 1.96 se above ~100; about 85% at 13 and 65% at 3: tests/stats)."""
        return self.n / self.g

    def __iter__(self):  # slope, se = drift(t, y)
        return iter((self.slope, self.se))


def drift(t, y) -> Drift:
    """The slope of the least-squares line through y(t) and its standard error (correlated residuals)."""
    t = np.asarray(t, dtype=np.float64)
    y = np.asarray(y, dtype=np.float64)
    if t.shape != y.shape or t.ndim != 1:
        raise InputError(f"t and y must be 1-d arrays of one length, got shapes {t.shape} and {y.shape}")
    n = len(t)
    if n < 3:
        raise InputError(f"a drift needs at least 3 samples, got {n}")
    tc = t - t.mean()
    sxx = float(tc @ tc)
    if not sxx > 0:
        raise InputError("a drift needs samples at more than one time")
    slope = float(tc @ (y - y.mean())) / sxx
    resid = y - y.mean() - slope * tc
    g = statistical_inefficiency(resid)
    s2 = float(resid @ resid) / (n - 2)
    return Drift(slope, float(np.sqrt(s2 * g / sxx)), g, n)


class RunningLine:
    """The least-squares line through (t, y) samples added one at a time (Welford-style co-moments: O(1) work
    and memory per sample, no loss of precision for long runs).  ``slope`` is what :func:`drift` gives for the
    same samples; ``se_uncorrelated`` is its standard error if the samples were independent (the correlation
    correction needs the whole series: use :func:`drift` on stored samples)."""

    def __init__(self):
        self.n = 0
        self._mt = self._my = self._ctt = self._cty = self._cyy = 0.0

    def add(self, t: float, y: float) -> "RunningLine":
        self.n += 1
        dt = t - self._mt
        dy = y - self._my
        self._mt += dt / self.n
        self._my += dy / self.n
        self._ctt += dt * (t - self._mt)
        self._cty += dt * (y - self._my)
        self._cyy += dy * (y - self._my)
        return self

    @property
    def slope(self) -> float:
        """The slope, NaN before two samples at different times."""
        return self._cty / self._ctt if self._ctt > 0 else float("nan")

    @property
    def se_uncorrelated(self) -> float:
        if self.n < 3 or not self._ctt > 0:
            return float("nan")
        ssr = max(self._cyy - self._cty ** 2 / self._ctt, 0.0)
        return float(np.sqrt(ssr / (self.n - 2) / self._ctt))
