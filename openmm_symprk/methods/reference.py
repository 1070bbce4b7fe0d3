"""Reference integrators in pure numpy, for separable H = p^2/2m + V(q).

These run any catalogue method or user tableau on small model problems in float64 or long double,
so that orders and conservation can be *measured* in milliseconds, without OpenMM
(:mod:`.stability` does the same for stability intervals).  The OpenMM programs compiled by
:mod:`openmm_symprk.integrators.program` follow the same semantics.
"""
from __future__ import annotations

from typing import Callable

import numpy as np

from .orders import observed_orders
from .resolved import resolve
from .splitting import KICK, Splitting
from .tableau import PRKTableau
from ..support.errors import SymprkError


class ConvergenceError(SymprkError, RuntimeError):
    """The fixed-point iteration of an implicit method did not converge."""


# -- model problems -----------------------------------------------------------------------------
def henon_heiles_force(q):
    """Force of V = (x^2 + y^2)/2 + x^2 y - y^3/3 (2 degrees of freedom, nonlinear, smooth)."""
    x, y = q[..., 0], q[..., 1]
    return np.stack([-x - 2 * x * y, -y - x * x + y * y], axis=-1)


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
    """Integrate ``n_steps`` steps of a method name, catalogue Method, Splitting, PRKTableau or ResolvedMethod
    (resolved without constraints: a model problem has none).

    A kick/drift method runs its sequence; a PRKTableau given as such (even one in splitting form) and every
    general pair run their stages.  Returns (q, p) at the end, or arrays of shape (n_steps+1, ...) with
    ``trajectory=True``."""
    r = resolve(method)
    q = np.array(q0, dtype=dtype)
    p = np.array(p0, dtype=dtype)
    h = dtype(h) if not isinstance(h, np.ndarray) else h.astype(dtype)
    if r.is_splitting and not isinstance(method, PRKTableau):
        coeffs = r.splitting.coefficients(dtype)
        step = lambda q, p: splitting_step(r.splitting, force, q, p, h, coefficients=coeffs)
    else:
        tab = r.tableau_in(dtype)
        step = lambda q, p: prk_step(tab, force, q, p, h)
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
    return observed_orders(ys, steps)
