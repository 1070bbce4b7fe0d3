"""Reference integrators in pure numpy, for separable H = p^2/2m + V(q).

These run any catalogue method or user tableau on small model problems in float64 or long double,
so that orders, stability intervals and conservation can be *measured* in milliseconds, without
OpenMM.  The OpenMM programs compiled by :mod:`openmm_symprk.program` follow the same semantics.
"""
from __future__ import annotations

import math
from typing import Callable

import numpy as np

from .splitting import DRIFT, KICK, Splitting
from .tableau import PRKTableau


class ConvergenceError(RuntimeError):
    """The fixed-point iteration of an implicit method did not converge."""


# -- model problems -----------------------------------------------------------------------------
def henon_heiles_force(q):
    """Force of V = (x^2 + y^2)/2 + x^2 y - y^3/3 (2 degrees of freedom, nonlinear, smooth)."""
    x, y = q[..., 0], q[..., 1]
    return np.stack([-x - 2 * x * y, -y - x * x + y * y], axis=-1)


def henon_heiles_energy(q, p):
    x, y = q[..., 0], q[..., 1]
    return 0.5 * np.sum(p * p, axis=-1) + 0.5 * (x * x + y * y) + x * x * y - y ** 3 / 3


def pendulum_force(q):
    return -np.sin(q)


def harmonic_force(q):
    return -q


def central_force(q, k=1.0):
    """Anharmonic central potential V = k (|q|^2/2 + |q|^4/4) in 3-D: conserves L = q x p."""
    r2 = np.sum(q * q, axis=-1, keepdims=True)
    return -k * q * (1 + r2)


# -- one step -----------------------------------------------------------------------------------
def splitting_step(splitting: Splitting, force: Callable, q, p, h, dtype=None, coefficients=None):
    """One step of a kick/drift sequence (unit masses)."""
    coeffs = coefficients if coefficients is not None else splitting.coefficients(dtype or q.dtype)
    for label, c in coeffs:
        if label == KICK:
            p = p + (c * h) * force(q)
        else:
            q = q + (c * h) * p
    return q, p


def prk_step(tab: PRKTableau, force: Callable, q, p, h, tol=None, max_iter=100):
    """One step of a (possibly implicit) PRK pair, stages solved by fixed-point iteration."""
    s = tab.stages
    A, Ah, b, bh = tab.A, tab.A_hat, tab.b, tab.b_hat
    order = tab.explicit_order
    Q = np.repeat(q[None], s, axis=0)
    P = np.repeat(p[None], s, axis=0)
    F = np.zeros_like(Q)
    if order == "q-first":
        for i in range(s):
            Q[i] = q + h * np.tensordot(A[i, :i], P[:i], axes=1)
            F[i] = force(Q[i])
            P[i] = p + h * np.tensordot(Ah[i, :i + 1], F[:i + 1], axes=1)
    elif order == "p-first":
        for i in range(s):
            P[i] = p + h * np.tensordot(Ah[i, :i], F[:i], axes=1)
            Q[i] = q + h * np.tensordot(A[i, :i + 1], P[:i + 1], axes=1)
            F[i] = force(Q[i])
    else:
        tol = tol if tol is not None else 10 * np.finfo(q.dtype).eps
        for it in range(max_iter):
            F = np.stack([force(Qi) for Qi in Q])
            P = p + h * np.tensordot(Ah, F, axes=1)
            Qn = q + h * np.tensordot(A, P, axes=1)
            delta = np.max(np.abs(Qn - Q))
            Q = Qn
            if delta <= tol * max(1.0, float(np.max(np.abs(q)))):
                break
        else:
            raise ConvergenceError(f"{tab.name}: fixed-point iteration did not converge in {max_iter} iterations "
                                   f"(last change {float(delta):.3e}); reduce the step size")
        F = np.stack([force(Qi) for Qi in Q])
        P = p + h * np.tensordot(Ah, F, axes=1)
    return q + h * np.tensordot(b, P, axes=1), p + h * np.tensordot(bh, F, axes=1)


def integrate(method, force: Callable, q0, p0, h, n_steps: int, dtype=np.float64, trajectory=False):
    """Integrate ``n_steps`` steps of a catalogue Method, Splitting or PRKTableau.

    Returns (q, p) at the end, or arrays of shape (n_steps+1, ...) with ``trajectory=True``."""
    from .catalogue import Method, get_method

    if isinstance(method, str):
        method = get_method(method)
    q = np.array(q0, dtype=dtype)
    p = np.array(p0, dtype=dtype)
    h = dtype(h) if not isinstance(h, np.ndarray) else h.astype(dtype)
    if isinstance(method, Method):
        method = method.splitting if method.is_splitting else method.tableau(dtype)
    if isinstance(method, Splitting):
        coeffs = method.coefficients(dtype)
        step = lambda q, p: splitting_step(method, force, q, p, h, coefficients=coeffs)
    elif isinstance(method, PRKTableau):
        if method.dtype != np.dtype(dtype):
            method = PRKTableau(method.A, method.b, method.A_hat, method.b_hat, name=method.name, dtype=dtype)
        step = lambda q, p: prk_step(method, force, q, p, h)
    else:
        raise TypeError(f"expected a method name, Method, Splitting or PRKTableau, got {method!r}")
    qs, ps = [q], [p]
    for _ in range(n_steps):
        q, p = step(q, p)
        if trajectory:
            qs.append(q)
            ps.append(p)
    if trajectory:
        return np.array(qs), np.array(ps)
    return q, p


# -- measured properties ------------------------------------------------------------------------
def measure_order(method, force=henon_heiles_force, q0=(0.1, 0.3), p0=(0.35, -0.1), T=2.0,
                  steps=(4, 8, 16, 32, 64), dtype=np.longdouble):
    """Observed order from successive halvings: log2(|y_N - y_2N| / |y_2N - y_4N|).

    Returns (orders, differences) with one order estimate per consecutive triple of step counts.
    No reference solution is needed, so a wrong coefficient cannot hide behind a wrong reference."""
    ys = []
    for n in steps:
        q, p = integrate(method, force, q0, p0, dtype(T) / n, n, dtype=dtype)
        ys.append(np.concatenate([q, p]))
    diffs = np.array([float(np.max(np.abs(a - b))) for a, b in zip(ys, ys[1:])])
    with np.errstate(divide="ignore"):
        orders = np.log2(diffs[:-1] / diffs[1:]) / np.log2(np.array(steps[1:-1]) / np.array(steps[:-2]))
    return orders, diffs


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
    # Eigenvalues lambda = tr +- sqrt(tr^2 - det); bounded iff |lambda| <= 1 (and not a Jordan block).
    disc = tr * tr - det
    root = np.sqrt(np.abs(disc))
    rad = np.where(disc >= 0, np.maximum(np.abs(tr + root), np.abs(tr - root)), np.sqrt(np.abs(det)))
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
    from scipy.optimize import minimize_scalar

    from .catalogue import Method, get_method

    if isinstance(method, str):
        method = get_method(method)
    tab = method.tableau() if isinstance(method, Method) else (
        PRKTableau.from_splitting(method) if isinstance(method, Splitting) else method)
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
