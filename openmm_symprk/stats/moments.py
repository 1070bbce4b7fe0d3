"""Mean and variance of independent draws, with their standard errors, from power sums.

A generator's output is judged by the first moments of many independent draws: the mean with its standard error
sqrt(var/n), and the variance with the standard error of the sample variance, sqrt((mu4 - mu2^2)/n) (mu_k the central
moments).  The sums may be accumulated where the draws are made (a CustomIntegrator program, a chunked loop) as power
sums of ``x - shift``: a shift near the mean (the known answer) keeps them free of cancellation.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..support.errors import InputError

__all__ = ["Moments", "power_sums", "correlation"]


def power_sums(x, shift: float = 0.0) -> np.ndarray:
    """(S1, S2, S3, S4): the sums of (x - shift)^p for p = 1..4, in float64."""
    y = np.asarray(x, dtype=np.float64) - shift
    y2 = y * y
    return np.array([y.sum(), y2.sum(), (y2 * y).sum(), (y2 * y2).sum()])


@dataclass(frozen=True)
class Moments:
    """``n`` independent draws: ``mean`` and ``variance`` (unbiased), each with its standard error."""

    n: int
    mean: float
    mean_se: float
    variance: float
    variance_se: float

    @classmethod
    def from_power_sums(cls, n: int, sums, shift: float = 0.0) -> "Moments":
        """From ``sums`` = (S1, S2, S3, S4) of (x - shift)^p over ``n`` >= 2 draws (:func:`power_sums`)."""
        n = int(n)
        if n < 2:
            raise InputError(f"moments need at least 2 draws, got {n}")
        s1, s2, s3, s4 = (float(s) / n for s in sums)
        mu2 = s2 - s1 * s1
        mu4 = s4 - 4 * s1 * s3 + 6 * s1 * s1 * s2 - 3 * s1 ** 4
        variance = mu2 * n / (n - 1)
        return cls(n, shift + s1, math.sqrt(max(variance, 0.0) / n), variance,
                   math.sqrt(max(mu4 - mu2 * mu2, 0.0) / n))

    @classmethod
    def of(cls, x, shift: float = 0.0) -> "Moments":
        """The moments of the draws ``x``."""
        return cls.from_power_sums(len(x), power_sums(x, shift), shift)

    def mean_z(self, expected: float) -> float:
        """(mean - expected) in standard errors."""
        return (self.mean - expected) / self.mean_se

    def variance_z(self, expected: float) -> float:
        """(variance - expected) in standard errors."""
        return (self.variance - expected) / self.variance_se


def correlation(n: int, sum_xy: float, x: Moments, y: Moments, shift_x: float = 0.0, shift_y: float = 0.0) -> float:
    """The correlation coefficient of two series of ``n`` pairs from the sum of (x - shift_x)(y - shift_y) and the
    series' moments; about N(0, 1/n) for independent ones."""
    cov = sum_xy / n - (x.mean - shift_x) * (y.mean - shift_y)
    return cov / math.sqrt(x.variance * y.variance)
