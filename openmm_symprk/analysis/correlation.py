"""Time correlation functions averaged over time origins, by FFT (pure numpy).

For a series a(t_k), k = 0..n-1, sampled every dt, the correlation at lag m averaged over every time origin is

    c(m) = 1/(n - m) sum_{k=0}^{n-m-1} a(k) a(k + m),

computed in O(n log n) with a zero-padded FFT (Wiener-Khinchin) instead of the O(n^2) double loop.  Long
lags average few origins (n - m): they are noisy, and the callers stop at a stated maximum lag.

Error bars of figures computed from a molecule-averaged correlation function (a correlation time, a first
minimum) come from the delete-one-group jackknife over molecules, :func:`openmm_symprk.stats.jackknife`.
"""
from __future__ import annotations

import numpy as np

from ..support.errors import InputError

__all__ = ["origin_averaged_correlation", "check_max_lag"]


def check_max_lag(n_frames: int, max_lag: int | None) -> int:
    """The maximum lag (frames) for a series of ``n_frames``: ``max_lag``, or n_frames // 2 when None."""
    if n_frames < 2:
        raise InputError(f"a correlation needs at least 2 frames, got {n_frames}")
    if max_lag is None:
        return n_frames // 2
    max_lag = int(max_lag)
    if not 1 <= max_lag <= n_frames - 1:
        raise InputError(f"max_lag must be between 1 and n_frames - 1 = {n_frames - 1} frames, got {max_lag}")
    return max_lag


def origin_averaged_correlation(a, max_lag: int | None = None, chunk: int = 256) -> np.ndarray:
    """c(m) = <a(t0) a(t0 + m)> averaged over time origins t0, for every series in ``a``.

    ``a``: (n_frames, ...) - time first, any number of independent series after it.  Returns
    (max_lag + 1, ...), lags 0..max_lag frames (default n_frames // 2), same trailing shape, float64.  The
    series are transformed ``chunk`` at a time (the padded transforms of all at once would hold 8 times the
    input).
    """
    a = np.asarray(a)
    n = a.shape[0]
    max_lag = check_max_lag(n, max_lag)
    size = 1 << int(np.ceil(np.log2(2 * n)))  # zero padding to >= 2n: no wrap-around
    flat = a.reshape(n, -1)
    out = np.empty((max_lag + 1, flat.shape[1]))
    for k in range(0, flat.shape[1], chunk):
        f = np.fft.rfft(flat[:, k:k + chunk].astype(np.float64), size, axis=0)
        f *= np.conj(f)
        out[:, k:k + chunk] = np.fft.irfft(f, size, axis=0)[:max_lag + 1]
    out /= (n - np.arange(max_lag + 1))[:, None]
    return out.reshape((max_lag + 1,) + a.shape[1:])
