"""Linear stability of PRK methods on the harmonic oscillator q'' = -omega^2 q (pure numpy and scipy).

A method is stable at h*omega = x if its 2x2 one-step matrix M(x) has no eigenvalue of modulus above 1.
:func:`stability_interval` finds the largest x such that every step in (0, x] is stable, including
narrow resonance bands that a plain grid would miss.  :func:`spectral_radius` is the one 2x2 eigenvalue
formula of the package (the bench's linear probe uses it on matrices measured from OpenMM).
"""
from __future__ import annotations

import math

import numpy as np

from .resolved import resolve
from .tableau import PRKTableau


def spectral_radius(m11, m12, m21, m22):
    """Largest |eigenvalue| of a batch of 2x2 matrices [[m11, m12], [m21, m22]] (arrays broadcast)."""
    half_tr = 0.5 * (np.asarray(m11) + np.asarray(m22))
    det = np.asarray(m11) * np.asarray(m22) - np.asarray(m12) * np.asarray(m21)
    disc = half_tr * half_tr - det
    with np.errstate(invalid="ignore"):
        root = np.sqrt(np.abs(disc))
        real = np.maximum(np.abs(half_tr + root), np.abs(half_tr - root))
        cplx = np.sqrt(np.abs(half_tr * half_tr + np.abs(disc)))  # |tr/2 +- i sqrt(-disc)|
    return np.where(disc >= 0, real, cplx)


def propagation_matrices(tab: PRKTableau, x):
    """The 2x2 one-step matrices of the PRK pair on q'' = -q at steps h = x (array), batched.

    The stage equations Q = q e + h A P, P = p e - h A_hat Q are linear; solve them exactly."""
    x = np.atleast_1d(np.asarray(x, dtype=np.float64))
    s = tab.stages
    A, Ah, b, bh = (np.asarray(m, dtype=np.float64) for m in (tab.A, tab.A_hat, tab.b, tab.b_hat))
    I = np.eye(s)
    e = np.ones(s)
    n = x.size
    # Unknowns z = [Q; P]: [[I, -hA], [hAh, I]] z = [q e; p e]
    K = np.zeros((n, 2 * s, 2 * s))
    K[:, :s, :s] = I
    K[:, s:, s:] = I
    K[:, :s, s:] = -x[:, None, None] * A
    K[:, s:, :s] = x[:, None, None] * Ah
    rhs = np.zeros((2 * s, 2))
    rhs[:s, 0] = e
    rhs[s:, 1] = e
    Z = np.linalg.solve(K, np.broadcast_to(rhs, (n, 2 * s, 2)))  # columns: response to q=1, p=1
    Q, P = Z[:, :s, :], Z[:, s:, :]
    M = np.zeros((n, 2, 2))
    M[:, 0, :] = np.array([1.0, 0.0]) + x[:, None] * np.einsum("i,nij->nj", b, P)
    M[:, 1, :] = np.array([0.0, 1.0]) - x[:, None] * np.einsum("i,nij->nj", bh, Q)
    return M


def _margin(tab, x):
    """1 - spectral radius of the one-step matrix (>= 0 where stable), batched over x."""
    M = propagation_matrices(tab, x)
    tr = 0.5 * (M[:, 0, 0] + M[:, 1, 1])
    det = M[:, 0, 0] * M[:, 1, 1] - M[:, 0, 1] * M[:, 1, 0]
    rad = spectral_radius(M[:, 0, 0], M[:, 0, 1], M[:, 1, 0], M[:, 1, 1])
    # An area-preserving map (det = 1, every symplectic method) is stable iff |tr/2| <= 1; 1 - |tr/2| is a
    # smooth margin whose local minima reveal narrow instability bands (the radius would be flat at 1).
    return np.where(np.abs(det - 1.0) < 1e-9, 1.0 - np.abs(tr), 1.0 - rad)


def _stable(tab, x):
    return _margin(tab, x) >= -1e-12


def stability_interval(method, x_max: float = 20.0, resolution: float = 1e-3, tol: float = 1e-10) -> float:
    """Largest h*omega such that the method is stable on q'' = -omega^2 q for every step in (0, h*omega].

    Scans (0, x_max] on a grid.  Instability bands narrower than the grid (high-order compositions have
    them, e.g. sofroniou-spaletta-10 near h*omega = pi) show up as local minima of the stability margin
    1 - spectral radius that come close to zero; each such minimum is refined by a bounded scalar
    minimisation.  The first unstable point found is then bisected against the last stable one to
    ``tol``.  Returns inf if the method is stable on the whole scan range."""
    from ..support import require

    minimize_scalar = require("scipy.optimize", "analysis", "openmm_symprk.methods.stability.stability_interval"
                              ).minimize_scalar

    tab = resolve(method).tableau_in(np.float64)  # the method's own PRK pair (a name, Method, Splitting, ...)
    grid = np.arange(resolution, x_max + resolution, resolution)
    g = _margin(tab, grid)
    first_bad = None
    bad = np.flatnonzero(g < -1e-12)
    if bad.size:
        first_bad = grid[bad[0]]
    # narrow bands: local minima of the margin below 1e-2 before the first unstable grid point
    interior = np.flatnonzero((g[1:-1] <= g[:-2]) & (g[1:-1] <= g[2:]) & (g[1:-1] < 1e-2)) + 1
    for i in interior:
        if first_bad is not None and grid[i] >= first_bad:
            break
        res = minimize_scalar(lambda y: float(_margin(tab, y)[0]), bounds=(grid[i - 1], grid[i + 1]),
                              method="bounded", options={"xatol": 1e-12})
        if res.fun < -1e-12:
            first_bad = float(res.x)
            break
    if first_bad is None:
        return math.inf
    below = grid[grid < first_bad]
    lo = below[-1] if below.size else 0.0
    hi = first_bad
    # the band may start anywhere in (lo, hi): step towards it on a fine sub-grid first
    sub = np.linspace(lo, hi, 65)
    sub_bad = np.flatnonzero(~_stable(tab, sub))
    lo, hi = sub[sub_bad[0] - 1], sub[sub_bad[0]]
    while hi - lo > tol:
        mid = 0.5 * (lo + hi)
        if _stable(tab, mid)[0]:
            lo = mid
        else:
            hi = mid
    return lo
