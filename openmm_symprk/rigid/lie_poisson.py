"""Lie-Poisson integrators for the free rigid body (Euler's equations), pure numpy/scipy.

Euler's equations for the body angular momentum ``x`` of a torque-free rigid body with principal
moments of inertia ``M = (M1, M2, M3)`` (any order, all positive) are

    x' = x × M⁻¹x,        H(x) = ½ xᵀM⁻¹x (energy),   C(x) = |x|² (Casimir).

This module implements the integrators of section 5 of Reich (1994) (docs/theory.md, section 3):

``splitting-1``
    exp(hX1) exp(hX2) exp(hX3), where X_i is the flow of H_i = ½ x_i²/M_i, an exact rotation of x
    about body axis i by the angle -h x_i/M_i.  Order 1.
``splitting-2``
    X1(h/2) X2(h/2) X3(h) X2(h/2) X1(h/2), the NO_SQUISH rotation sequence.  Order 2, symmetric.
``splitting-4``, ``splitting-6`` and every composition of the catalogue (``yoshida-4``, ``kahan-li-8``, ...)
    ``splitting-2`` composed with the catalogue's composition weights through
    :func:`openmm_symprk.methods.splitting.compose`, the code path that builds the MD kick/drift compositions.
``rattle-1``
    Reduced RATTLE / constrained symplectic Euler on SO(3) (Reich's Example 5.3), with a Newton solve
    for the symmetric multiplier.  Constrained symplectic Euler is first order in general, but the free
    rigid body has no potential, so the step coincides with RATTLE (a kick of zero force) and is
    symmetric: it is the discrete Moser-Veselov rigid body, of order 2, and it also conserves the
    energy to round-off.  Measured: order 2.0 (see the tests); hence ``METHODS['rattle-1'].order == 2``.
``rk4``
    Classical Runge-Kutta, the catalogue's tableau run on x' = f(x): the non-Poisson reference, it does not
    stay on the sphere |x| = const.

Names go through the catalogue (:func:`rigid_body_method`): ``splitting-1``, ``splitting-2`` and ``rattle-1`` are
the integrators of Euler's equations only; every other name, alias, catalogue Method or resolved method is the
catalogue's (``splitting-4``/``splitting-6`` are Reich's names for ``yoshida-4``/``yoshida-6``), and an unknown name
gets the close ones.  :data:`METHODS` lists them all.

All Lie-Poisson methods conserve the Casimir |x|² to round-off; every step is a composition of
rotations of x.

The exact solution (:func:`exact_solution`) uses Jacobi elliptic functions (Landau & Lifshitz,
Mechanics §37) in both energy regimes, with closed forms for symmetric and spherical tops.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from ..methods.catalogue import UnknownMethodError, normalise_name
from ..methods.catalogue import methods as catalogue_methods
from ..methods.resolved import resolve
from ..methods.splitting import Splitting, compose
from ..support import InputError, require

__all__ = [
    "METHODS", "RigidBodyMethod", "rigid_body_method", "euler_rhs", "energy", "casimir", "integrate", "step",
    "exact_solution", "splitting_of", "rattle_step", "second_moments",
]


# -- the methods ----------------------------------------------------------------------------------
@dataclass(frozen=True)
class RigidBodyMethod:
    name: str
    order: int
    lie_poisson: bool  # stays on the coadjoint orbit |x| = const and is a Poisson map
    description: str
    catalogue: str | None = None  # the catalogue method it runs (compositions: their weights over splitting-2)


#: Symmetric second-order base step: X1(h/2) X2(h/2) X3(h) X2(h/2) X1(h/2) (NO_SQUISH).
SPLITTING_2 = Splitting([("X1", "1/2"), ("X2", "1/2"), ("X3", 1), ("X2", "1/2"), ("X1", "1/2")])
SPLITTING_1 = Splitting([("X1", 1), ("X2", 1), ("X3", 1)])

#: The integrators of Euler's equations that are not catalogue methods (Reich, section 5).  Reduced RATTLE is
#: Reich's constrained symplectic Euler; with no potential it is RATTLE itself, hence order 2.
EULER_METHODS = {
    "splitting-1": RigidBodyMethod("splitting-1", 1, True, "exp(hX1) exp(hX2) exp(hX3)"),
    "splitting-2": RigidBodyMethod("splitting-2", 2, True,
                                   "X1(h/2) X2(h/2) X3(h) X2(h/2) X1(h/2) (NO_SQUISH sequence)"),
    "rattle-1": RigidBodyMethod("rattle-1", 2, True,
                                "reduced RATTLE / constrained symplectic Euler on SO(3) (Example 5.3)"),
}
#: Reich's names for two catalogue compositions over splitting-2.
COMPOSITION_NAMES = {"splitting-4": "yoshida-4", "splitting-6": "yoshida-6"}


def _runs_on_euler(entry) -> bool:
    """Catalogue methods with a rigid-body form: compositions (over splitting-2) and explicit reference tableaux
    (stages on x' = f(x))."""
    return entry.family == "composition" or (entry.family == "reference" and entry.tableau().is_explicit)


def rigid_body_method(method) -> RigidBodyMethod:
    """The rigid-body integrator of ``method``: a name of :data:`EULER_METHODS` or :data:`COMPOSITION_NAMES`, or a
    catalogue composition or explicit reference method (a name or alias, a catalogue Method or a resolved one).
    UnknownMethodError (a ValueError) with the close names for a name that is neither; ValueError for a catalogue
    method without a rigid-body form."""
    if isinstance(method, RigidBodyMethod):
        return method
    key = normalise_name(method) if isinstance(method, str) else None
    if key in EULER_METHODS:
        return EULER_METHODS[key]
    shown = key if key in COMPOSITION_NAMES else None
    try:
        entry = resolve(COMPOSITION_NAMES.get(key, method)).entry
    except UnknownMethodError:
        raise UnknownMethodError(
            f"unknown rigid-body method {method!r}."
            f"{catalogue_methods.suggest(method, among=_EULER_CATALOGUE, extra=[*EULER_METHODS, *COMPOSITION_NAMES])}"
            f" Known methods: {', '.join(METHODS)}.") from None
    except TypeError:
        raise InputError(f"method must be a name (one of {', '.join(METHODS)}) or a catalogue method, got "
                         f"{method!r}") from None
    if entry is None or not _runs_on_euler(entry):
        what = "a user method" if entry is None else f"the catalogue's {entry.name!r} ({entry.family})"
        raise InputError(f"{what} has no rigid-body form: Euler's equations run {', '.join(EULER_METHODS)}, the "
                         f"catalogue's compositions (over splitting-2) and explicit reference methods (rk4)")
    if entry.family == "composition":
        return RigidBodyMethod(shown or entry.name, entry.order, True,
                               f"splitting-2 composed with the {entry.name} weights", entry.name)
    return RigidBodyMethod(entry.name, entry.order, False, f"the catalogue's {entry.name} tableau on x' = x × M⁻¹x "
                                                           f"(not Lie-Poisson)", entry.name)


_EULER_CATALOGUE = [m for m in catalogue_methods.values() if _runs_on_euler(m)]
#: name -> :class:`RigidBodyMethod` of every method (order, whether Lie-Poisson, description): a listing built from
#: :data:`EULER_METHODS`, :data:`COMPOSITION_NAMES` and the catalogue.
METHODS: dict = {name: rigid_body_method(name) for name in
                 [*EULER_METHODS, *COMPOSITION_NAMES, *(m.name for m in _EULER_CATALOGUE)]}


@lru_cache(maxsize=None)
def _splitting(info: RigidBodyMethod) -> Splitting:
    if info.name == "splitting-1":
        return SPLITTING_1
    if info.name == "splitting-2":
        return SPLITTING_2
    if not info.lie_poisson or info.catalogue is None:
        raise InputError(f"method {info.name!r} is not a splitting of Euler's equations")
    return compose(SPLITTING_2, catalogue_methods[info.catalogue].weights)


def splitting_of(method) -> Splitting:
    """The X1/X2/X3 sub-flow sequence of a splitting method (a :class:`Splitting`)."""
    return _splitting(rigid_body_method(method))


# -- input checks --------------------------------------------------------------------------------
def _check_moments(moments) -> np.ndarray:
    m = np.asarray(moments, dtype=float)
    if m.shape != (3,):
        raise InputError(f"moments must be 3 principal moments of inertia, got shape {m.shape}")
    if not np.all(np.isfinite(m)) or np.any(m <= 0):
        raise InputError(f"principal moments of inertia must be finite and positive, got {m.tolist()}")
    return m


def _check_x(x0) -> np.ndarray:
    x = np.asarray(x0, dtype=float)
    if x.shape != (3,):
        raise InputError(f"x0 must be a body angular momentum vector of shape (3,), got shape {x.shape}")
    if not np.all(np.isfinite(x)):
        raise InputError(f"x0 must be finite, got {x.tolist()}")
    return x


# -- the vector field and its invariants -------------------------------------------------------
def euler_rhs(x, moments):
    """Right-hand side x × M⁻¹x of Euler's equations (x of shape (..., 3))."""
    x = np.asarray(x, dtype=float)
    return np.cross(x, x / np.asarray(moments, dtype=float))


def energy(x, moments):
    """Kinetic energy ½ Σ x_i²/M_i (x of shape (..., 3))."""
    x = np.asarray(x, dtype=float)
    return 0.5 * np.sum(x * x / np.asarray(moments, dtype=float), axis=-1)


def casimir(x):
    """The Casimir |x|² (x of shape (..., 3))."""
    x = np.asarray(x, dtype=float)
    return np.sum(x * x, axis=-1)


# -- exact sub-flows -----------------------------------------------------------------------------
_NEXT = ((1, 2), (2, 0), (0, 1))  # (j, k) with (i, j, k) cyclic


def _run_splitting(x0, inv_m, h, n_steps, splitting: Splitting):
    # Coefficients come from the Splitting (exact fractions -> float64) in the order it applies them.
    seq = [(int(label[1]) - 1, float(c) * h) for label, c in splitting.coefficients()]
    out = np.empty((n_steps + 1, 3))
    x = [float(v) for v in x0]
    out[0] = x
    cos, sin = math.cos, math.sin
    for n in range(1, n_steps + 1):
        for i, dt in seq:
            # Flow of H_i = x_i²/(2 M_i): x' = x × (x_i/M_i) e_i, a rotation about e_i by -dt x_i/M_i.
            j, k = _NEXT[i]
            angle = -dt * inv_m[i] * x[i]
            c, s = cos(angle), sin(angle)
            xj, xk = x[j], x[k]
            x[j] = c * xj - s * xk
            x[k] = s * xj + c * xk
        out[n] = x
    return out


# -- reduced RATTLE (Example 5.3) ----------------------------------------------------------------
def second_moments(moments) -> np.ndarray:
    """Diagonal J of the Lagrangian ½ tr(q' J q'ᵀ) on SO(3) whose Euler equations have moments M.

    With q' = q Ω (Ω skew, angular velocity ω) the kinetic energy ½ tr(ΩJΩᵀ) equals ½ ωᵀMω with
    M_i = J_j + J_k, so J_i = (M_j + M_k - M_i)/2 (the body's second moments ∫ r_i² dm).  This needs
    the strict triangle inequality between the moments (a body that is not planar or linear).  When
    it fails, M⁻¹ is shifted by c·I with c = 1/min(M): x × (M⁻¹ + cI)x = x × M⁻¹x, so Euler's equations
    are unchanged and the shifted moments always satisfy the inequality."""
    m = _check_moments(moments)
    j = 0.5 * (m.sum() - 2 * m)
    if np.all(j > 1e-12 * m.max()):
        return j
    shifted = 1.0 / (1.0 / m + 1.0 / m.min())
    return 0.5 * (shifted.sum() - 2 * shifted)


def _hat(v):
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


_SYM_BASIS = []
for _a, _b in ((0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2)):
    _e = np.zeros((3, 3))
    _e[_a, _b] = _e[_b, _a] = 1.0
    _SYM_BASIS.append(_e)
_IU = np.triu_indices(3)
_SYM_STACK = np.array(_SYM_BASIS)
_SYM_MAP = _SYM_STACK.reshape(6, 9).T  # 6 coordinates -> flattened symmetric 3x3


def rattle_step(x, J, h, tol=None, max_iter=50):
    """One step of the reduced RATTLE of Example 5.3, started at q_n = I, p_n = Π_n.

    Π_n is the skew matrix of x/2 (the skew part of qᵀp equals ½ hat(Mω) for p = q'J), and

        Q = I + h P J⁻¹,   P = Π_n - 2hλ,   QᵀQ = I        (λ symmetric: Newton's method)
        Π_{n+1} = Qᵀ(P - 2hQμ) = QᵀP - 2hμ,   Π_{n+1} skew  (μ = sym(QᵀP)/(2h), closed form)

    (here ∇g(Q)ᵀμ = 2Qμ for g(q) = qᵀq - I).  Since P = (Q - I)J/h, Π_{n+1} = QᵀΠ_nQ, i.e.
    x_{n+1} = Qᵀx_n, and that is how x_{n+1} is formed: as x_n + Eᵀx_n with E = Q - I = hPJ⁻¹, the
    Newton residual being the one of E + Eᵀ + EᵀE = QᵀQ - I, which avoids the rounding of I and keeps
    |x| to round-off.  Returns (x_{n+1}, details) with details a dict of Q, P, λ, μ, Π_{n+1} and the number
    of Newton iterations."""
    x = np.asarray(x, dtype=float)
    J = np.asarray(J, dtype=float)
    jinv = 1.0 / J
    pi_n = 0.5 * _hat(x)
    # Initial guess: the symmetric S = 2hλ that makes (Π_n - S)J⁻¹ skew (leading order in h).
    lam = pi_n * (J[:, None] - J[None, :]) / (J[:, None] + J[None, :]) / (2 * h)
    scale = h * np.abs(pi_n).max() * jinv.max()  # size of E = Q - I
    tol = 2 * np.finfo(float).eps * scale if tol is None else tol
    if not np.any(pi_n):
        return x.copy(), {"Q": np.eye(3), "P": pi_n, "lambda": np.zeros((3, 3)), "mu": np.zeros((3, 3)),
                          "Pi_next": pi_n, "iterations": 0}
    eye = np.eye(3)
    dq = -2 * h * h * _SYM_STACK * jinv  # dQ/dλ along each symmetric basis matrix (P J⁻¹ scales columns)
    dqt = dq.transpose(0, 2, 1)
    best = math.inf
    for it in range(1, max_iter + 1):
        P = pi_n - 2 * h * lam
        E = h * P * jinv  # Q = I + E; QᵀQ - I = E + Eᵀ + EᵀE, formed without the rounding of I
        F = (E + E.T + E.T @ E)[_IU]
        Q = eye + E
        res = np.abs(F).max()
        # Converged: at tolerance, or stalled at round-off level (the residual stopped decreasing).
        if res <= tol or (res <= 64 * tol and res >= best):
            break
        best = min(best, res)
        jac = (dqt @ Q + Q.T @ dq)[:, _IU[0], _IU[1]].T
        try:
            delta = np.linalg.solve(jac, -F)
        except np.linalg.LinAlgError:
            raise RuntimeError(f"rattle-1: singular Newton matrix for the multiplier at h={h}; "
                               f"the step size is too large for this state") from None
        lam = lam + (_SYM_MAP @ delta).reshape(3, 3)
    else:
        raise RuntimeError(
            f"rattle-1: Newton's method for the multiplier did not converge in {max_iter} iterations "
            f"(residual {res:.3g}); the step size h={h} is too large for this state")
    QtP = Q.T @ P
    mu = 0.5 * (QtP + QtP.T) / (2 * h)
    pi_next = QtP - 2 * h * mu
    x_next = x + E.T @ x
    return x_next, {"Q": Q, "P": P, "lambda": lam, "mu": mu, "Pi_next": pi_next, "iterations": it}


def _run_rattle(x0, moments, h, n_steps):
    J = second_moments(moments)
    out = np.empty((n_steps + 1, 3))
    out[0] = x0
    x = np.array(x0, dtype=float)
    for n in range(1, n_steps + 1):
        x, _ = rattle_step(x, J, h)
        out[n] = x
    return out


# -- explicit Runge-Kutta (the catalogue's reference methods) ---------------------------------------------------
def _run_explicit(x0, inv_m, h, n_steps, A, b):
    """An explicit Runge-Kutta tableau (A strictly lower triangular, weights b) on x' = x × M⁻¹x."""
    def f(y):
        w = y * inv_m
        return np.array([y[1] * w[2] - y[2] * w[1], y[2] * w[0] - y[0] * w[2], y[0] * w[1] - y[1] * w[0]])

    out = np.empty((n_steps + 1, 3))
    out[0] = x0
    x = np.array(x0, dtype=float)
    s = len(b)
    for n in range(1, n_steps + 1):
        k = np.empty((s, 3))
        for i in range(s):
            k[i] = f(x + h * (A[i, :i] @ k[:i]))
        x = x + h * (b @ k)
        out[n] = x
    return out


# -- public driver --------------------------------------------------------------------------------
def integrate(x0, moments, h, n_steps, method="splitting-2") -> np.ndarray:
    """Integrate Euler's equations; returns the path, shape (n_steps + 1, 3), row 0 = x0."""
    x0 = _check_x(x0)
    m = _check_moments(moments)
    h = float(h)
    if not (math.isfinite(h) and h > 0):
        raise InputError(f"step size h must be positive and finite, got {h!r}")
    if isinstance(n_steps, bool) or int(n_steps) != n_steps or n_steps < 0:
        raise InputError(f"n_steps must be a non-negative integer, got {n_steps!r}")
    n_steps = int(n_steps)
    info = rigid_body_method(method)
    if info.name == "rattle-1":
        return _run_rattle(x0, m, h, n_steps)
    if not info.lie_poisson:  # an explicit reference tableau of the catalogue (its positions part: x' = f(x))
        tab = catalogue_methods[info.catalogue].tableau()
        return _run_explicit(x0, 1.0 / m, h, n_steps, tab.A, tab.b)
    return _run_splitting(x0, 1.0 / m, h, n_steps, _splitting(info))


def step(x, moments, h, method="splitting-2") -> np.ndarray:
    """One step of ``method`` from x."""
    return integrate(x, moments, h, 1, method)[1]


# -- exact solution -------------------------------------------------------------------------------
def _parity(a, b, c) -> int:
    return 1 if (a, b, c) in ((0, 1, 2), (1, 2, 0), (2, 0, 1)) else -1


def exact_solution(x0, moments, times) -> np.ndarray:
    """Exact x(t) of Euler's equations at ``times`` (any real values), shape (len(times), 3).

    Asymmetric top: with b the axis of the middle moment, the motion circulates about the axis c of
    the largest moment when |x|² > 2E·M_b and about the smallest otherwise; a is the third axis and

        x_a = A_a cn(u, m),  x_b = σ A_b sn(u, m),  x_c = s_c A_c dn(u, m),  u = ω t + u0

    (Landau-Lifshitz §37), with σ, s_c fixed by x0 and by the sense of rotation (the ODE).  On the
    separatrix (m = 1) cn = dn = sech and sn = tanh.  Symmetric tops rotate about the distinct axis in
    closed form; a spherical top (or x = 0) stays put."""
    special = require("scipy.special", "analysis", "openmm_symprk.rigid.lie_poisson.exact_solution")
    ellipj, ellipk, ellipkinc = special.ellipj, special.ellipk, special.ellipkinc
    x0 = _check_x(x0)
    M = _check_moments(moments)
    t = np.atleast_1d(np.asarray(times, dtype=float))
    if t.ndim != 1:
        raise InputError(f"times must be a 1-D array of times, got shape {t.shape}")
    out = np.empty((t.size, 3))
    if not np.any(x0):
        out[:] = 0.0
        return out

    order = np.argsort(M, kind="stable")
    s, b, l = (int(i) for i in order)  # smallest, middle, largest moment
    rel = 1e-13
    eq_sb = M[b] - M[s] <= rel * M[b]
    eq_bl = M[l] - M[b] <= rel * M[l]
    if eq_sb and eq_bl:  # spherical top: M⁻¹x ∥ x
        out[:] = x0
        return out
    if eq_sb or eq_bl:  # symmetric top about the distinct axis d
        d = l if eq_sb else s
        pair = (s, b) if eq_sb else (b, l)
        m_eq = 0.5 * (M[pair[0]] + M[pair[1]])
        # x' = x_d (1/M_d - 1/M_eq) x × e_d: rotation about e_d by -x_d (1/M_d - 1/M_eq) t.
        rate = -x0[d] * (1.0 / M[d] - 1.0 / m_eq)
        j, k = _NEXT[d]
        ang = rate * t
        c, sn_ = np.cos(ang), np.sin(ang)
        out[:, d] = x0[d]
        out[:, j] = c * x0[j] - sn_ * x0[k]
        out[:, k] = sn_ * x0[j] + c * x0[k]
        return out

    x2 = x0 * x0
    # g = 2E M_b - |x|²; its sign picks the regime.  Written without the x_b² term (it cancels).
    g = x2[s] * (M[b] / M[s] - 1) + x2[l] * (M[b] / M[l] - 1)
    c_ax = l if g < 0 else s
    a_ax = s if c_ax == l else l
    Ia, Ib, Ic = M[a_ax], M[b], M[c_ax]
    xa, xb, xc = x0[a_ax], x0[b], x0[c_ax]
    # 2E I_c - L² and L² - 2E I_a, as sums of terms of one sign (no cancellation).
    e_c = x2[a_ax] * (Ic / Ia - 1) + x2[b] * (Ic / Ib - 1)
    e_a = x2[b] * (1 - Ia / Ib) + x2[c_ax] * (1 - Ia / Ic)
    A_a = math.sqrt(max(0.0, Ia * e_c / (Ic - Ia)))
    A_b = math.sqrt(max(0.0, Ib * e_c / (Ic - Ib)))
    A_c = math.sqrt(max(0.0, Ic * e_a / (Ic - Ia)))
    omega = math.sqrt((Ic - Ib) * e_a / (Ia * Ib * Ic))
    m = (Ib - Ia) * e_c / ((Ic - Ib) * e_a) if e_a != 0 else 0.0
    eps = _parity(a_ax, b, c_ax)
    s_c = 1.0 if xc >= 0 else -1.0
    res = np.empty((t.size, 3))
    if A_a == 0.0 and A_b == 0.0:  # steady rotation about axis c
        out[:] = x0
        return out
    if m < 1.0 - 1e-14:
        # x_a' = ε x_b x_c (1/I_c - 1/I_b) with d cn/du = -sn dn fixes σ.
        sigma = -eps * s_c * math.copysign(1.0, Ib - Ic)
        theta = math.atan2(sigma * xb * A_a, xa * A_b)  # amplitude: sn = sin θ, cn = cos θ
        u0 = ellipkinc(theta, m)
        period = 4.0 * ellipk(m)
        u = np.mod(omega * t + u0, period)
        sn, cn, dn, _ = ellipj(u, m)
        res[:, a_ax] = A_a * cn
        res[:, b] = sigma * A_b * sn
        res[:, c_ax] = s_c * A_c * dn
    else:  # separatrix: homoclinic orbit towards the unstable steady rotation about axis b
        if xa == 0.0 and xc == 0.0:
            out[:] = x0
            return out
        s_a = 1.0 if xa >= 0 else -1.0
        sigma = -eps * s_a * s_c * math.copysign(1.0, Ib - Ic)
        # sinh(u0) = tanh/sech = (x_b/(σA_b)) / (|x_a|/A_a)
        u0 = math.asinh(sigma * xb * A_a / (A_b * abs(xa))) if xa != 0.0 else \
            math.asinh(sigma * xb * A_c / (A_b * abs(xc)))
        u = omega * t + u0
        sech = 1.0 / np.cosh(u)
        res[:, a_ax] = s_a * A_a * sech
        res[:, b] = sigma * A_b * np.tanh(u)
        res[:, c_ax] = s_c * A_c * sech
    return res


# -- measured figures -----------------------------------------------------------------------------
def report(moments=(1.8, 0.7, 1.3), x0=(0.4, 1.1, -0.8), T=2.0) -> str:
    """Measured orders and conservation figures (what ``python -m openmm_symprk.rigid.lie_poisson`` prints)."""
    ladders = {"splitting-1": [32, 64, 128, 256], "splitting-2": [16, 32, 64, 128],
               "splitting-4": [8, 16, 32, 64], "splitting-6": [8, 12, 16, 24], "kahan-li-8": [2, 3, 4, 6],
               "rattle-1": [32, 64, 128, 256], "rk4": [16, 32, 64, 128]}
    m = _check_moments(moments)
    x0 = _check_x(x0)
    exact_end = exact_solution(x0, m, [T])[0]
    lines = [f"moments {m.tolist()}, x0 {x0.tolist()}; order: slope of log|x_N - x(T)| vs log h, T = {T}",
             "conservation: h = 0.05, 10^4 steps (t = 500): max relative |x|² and energy error, and the "
             "energy error's max over the first and last tenth",
             f"{'method':14s} {'order':>5s} {'measured':>8s} {'|x|² drift':>11s} {'energy err':>11s} "
             f"{'1st tenth':>10s} {'last tenth':>10s}"]
    for name, ns in ladders.items():
        ns = np.array(ns)
        errs = [np.linalg.norm(integrate(x0, m, T / n, n, name)[-1] - exact_end) for n in ns]
        p = np.polyfit(np.log(T / ns), np.log(errs), 1)[0]
        path = integrate(x0, m, 0.05, 10_000, name)
        c = casimir(path)
        e = energy(path, m)
        de = np.abs(e / e[0] - 1)
        lines.append(f"{name:14s} {METHODS[name].order:5d} {p:8.2f} {np.abs(c / c[0] - 1).max():11.2e} "
                     f"{de.max():11.2e} {de[1:1001].max():10.2e} {de[-1000:].max():10.2e}")
    return "\n".join(lines)


if __name__ == "__main__":
    print(report())
