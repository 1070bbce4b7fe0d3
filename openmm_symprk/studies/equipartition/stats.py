"""Error bars for time series from molecular dynamics (pure numpy).

A time series x_1..x_n sampled every dt has, for its mean, the variance sigma^2 g / n where g = 1 + 2 sum_k rho_k
is the statistical inefficiency (rho_k: the autocorrelation at lag k).  g is summed with Sokal's automatic
window (stop at the first lag M >= c * g(M), c = 5), which keeps the estimate's own noise small; the integrated
correlation time is tau = g dt / 2.

Independent replicas (NVE runs from different equilibrated states) give a second, model-free error: the scatter
of their means.  :func:`combine` reports the larger of the two, so neither an underestimated correlation time
nor a lucky handful of replicas makes an error bar too small.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["SeriesStats", "inefficiency", "series_stats", "drift", "combine", "Estimate", "agrees"]


def inefficiency(x, c: float = 5.0) -> float:
    """Statistical inefficiency g >= 1 of the series ``x`` (1 for uncorrelated samples)."""
    x = np.asarray(x, dtype=np.float64)
    n = len(x)
    if n < 4:
        return 1.0
    d = x - x.mean()
    var = float(d @ d) / n
    if var == 0.0:
        return 1.0
    f = np.fft.rfft(d, 2 * n)
    acf = np.fft.irfft(f * np.conj(f))[:n] / (var * np.arange(n, 0, -1))
    g = 1.0
    for m in range(1, n // 2):
        g += 2.0 * acf[m]
        if m >= c * g:
            break
    return max(1.0, float(g))


@dataclass
class SeriesStats:
    mean: float
    se: float  # standard error of the mean, correlation included
    tau: float  # integrated correlation time (units of dt)
    n: int


def series_stats(x, dt: float = 1.0) -> SeriesStats:
    """Mean, its standard error and the integrated correlation time of a series sampled every ``dt``."""
    x = np.asarray(x, dtype=np.float64)
    if len(x) < 2:
        raise ValueError(f"a series needs at least 2 samples, got {len(x)}")
    g = inefficiency(x)
    return SeriesStats(float(x.mean()), float(x.std(ddof=1) * np.sqrt(g / len(x))), 0.5 * g * dt, len(x))


def drift(t, y) -> tuple:
    """(slope, standard error) of a least-squares line through y(t); the error allows for correlated residuals."""
    t = np.asarray(t, dtype=np.float64)
    y = np.asarray(y, dtype=np.float64)
    if len(t) < 3:
        raise ValueError(f"a drift needs at least 3 samples, got {len(t)}")
    tc = t - t.mean()
    sxx = float(tc @ tc)
    slope = float(tc @ (y - y.mean())) / sxx
    resid = y - y.mean() - slope * tc
    g = inefficiency(resid)
    s2 = float(resid @ resid) / (len(t) - 2)
    return slope, float(np.sqrt(s2 * g / sxx))


@dataclass
class Estimate:
    mean: float
    se: float
    replicas: int
    se_within: float  # from the correlation-corrected errors of each replica
    se_between: float  # from the scatter of the replica means (nan for one replica)

    def __format__(self, spec):
        spec = spec or ".2f"
        return f"{format(self.mean, spec)} ± {format(self.se, spec)}"


def combine(means, ses) -> Estimate:
    """The mean over replicas and the larger of the two standard errors (within / between replicas)."""
    means = np.asarray(means, dtype=np.float64)
    ses = np.asarray(ses, dtype=np.float64)
    r = len(means)
    if r == 0:
        raise ValueError("no replicas to combine")
    within = float(np.sqrt((ses ** 2).sum()) / r)
    between = float(means.std(ddof=1) / np.sqrt(r)) if r > 1 else float("nan")
    se = within if not np.isfinite(between) else max(within, between)
    return Estimate(float(means.mean()), se, r, within, between)


def agrees(a: Estimate, b: Estimate, k: float = 2.0) -> bool:
    """|a - b| within ``k`` combined standard errors."""
    return abs(a.mean - b.mean) <= k * float(np.hypot(a.se, b.se))
