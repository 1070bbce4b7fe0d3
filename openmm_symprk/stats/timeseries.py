"""Correlated time series: statistical inefficiency, mean and its standard error.

A series x_1..x_n has, for its mean, the variance sigma^2 g / n, where g = 1 + 2 sum_k (1 - k/n) rho_k is the
statistical inefficiency (rho_k: the autocorrelation at lag k) and tau = g / 2 sampling intervals the
integrated correlation time (Sokal's convention: tau = 1/2 + sum_k rho_k).  g is pymbar's estimate (``pymbar.timeseries.statistical_inefficiency``: the
autocorrelation summed until it first drops to zero or below, Chodera, JCTC 12, 1799 (2016)); this module is the
one place that imports pymbar, silencing the banner and warning pymbar 4 prints on import.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..support import InputError, require

__all__ = ["statistical_inefficiency", "SeriesStats", "series_stats", "block_stats", "equilibrated_from", "pymbar_timeseries"]

_module = None


def pymbar_timeseries():
    """pymbar's ``timeseries`` module, imported once and quietly (pymbar 4 logs a JAX banner and a warning)."""
    global _module
    if _module is None:
        import contextlib
        import io
        import logging
        import warnings

        log = logging.getLogger("pymbar")
        level = log.level
        log.setLevel(logging.ERROR)
        try:
            with warnings.catch_warnings(), contextlib.redirect_stdout(io.StringIO()), \
                    contextlib.redirect_stderr(io.StringIO()):
                warnings.simplefilter("ignore")
                timeseries = require("pymbar.timeseries", "studies",
                                     "openmm_symprk.stats (error bars of correlated series)")
        finally:
            log.setLevel(level)
        _module = timeseries
    return _module


def statistical_inefficiency(x) -> float:
    """Statistical inefficiency g >= 1 of the series ``x`` (1 for uncorrelated samples, 1 for a constant one)."""
    x = np.asarray(x, dtype=np.float64)
    if len(x) < 4 or not np.ptp(x) > 0:
        return 1.0
    return float(pymbar_timeseries().statistical_inefficiency(x))


@dataclass
class SeriesStats:
    mean: float
    se: float  # standard error of the mean, correlation included
    tau: float  # integrated correlation time, g / 2 in units of dt
    n: int
    g: float = 1.0  # statistical inefficiency


def series_stats(x, dt: float = 1.0) -> SeriesStats:
    """Mean, its standard error and the integrated correlation time of a series sampled every ``dt``."""
    x = np.asarray(x, dtype=np.float64)
    if len(x) < 2:
        raise InputError(f"a series needs at least 2 samples, got {len(x)}")
    g = statistical_inefficiency(x)
    return SeriesStats(float(x.mean()), float(x.std(ddof=1) * np.sqrt(g / len(x))), 0.5 * g * dt, len(x), g)


def block_stats(x, n_blocks: int, dt: float = 1.0) -> SeriesStats:
    """Mean and its standard error from the spread of ``n_blocks`` consecutive block means (the last
    ``len(x) % n_blocks`` samples are left out of the blocks, not of the mean).  Use it where the autocorrelation
    changes sign before a slow tail, which the statistical inefficiency (summed to the first zero) misses: the
    kinetic energy of a thermostatted liquid oscillates (librations) and then relaxes over a few collision times.
    The blocks must be much longer than that tail; the error then has n_blocks - 1 degrees of freedom.  ``g`` and
    ``tau`` are the ones the block error implies (n se^2 / var)."""
    x = np.asarray(x, dtype=np.float64)
    if int(n_blocks) != n_blocks or n_blocks < 2:
        raise InputError(f"n_blocks must be an integer >= 2, got {n_blocks!r}")
    n_blocks = int(n_blocks)
    if len(x) < 2 * n_blocks:
        raise InputError(f"{n_blocks} blocks need at least {2 * n_blocks} samples, got {len(x)}")
    blocks = x[:len(x) - len(x) % n_blocks].reshape(n_blocks, -1).mean(axis=1)
    se = float(blocks.std(ddof=1) / np.sqrt(n_blocks))
    var = float(x.var(ddof=1))
    g = len(x) * se ** 2 / var if var > 0 else 1.0
    return SeriesStats(float(x.mean()), se, 0.5 * g * dt, len(x), g)


def equilibrated_from(x) -> int:
    """The first sample of the equilibrated part of ``x``: the start that maximises the number of effectively
    independent samples left (pymbar's ``detect_equilibration``, Chodera 2016); 0 for a series without a
    transient, and for one too short (under 10 samples) or constant."""
    x = np.asarray(x, dtype=np.float64)
    if len(x) < 10 or not np.ptp(x) > 0:
        return 0
    t0, _, _ = pymbar_timeseries().detect_equilibration(x, fast=True)
    return int(t0)
