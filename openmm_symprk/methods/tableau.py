"""Partitioned Runge-Kutta tableau pairs (pure numpy; no OpenMM import).

For q' = f(p), p' = g(q) (separable H; in MD f = M^-1 p, g = F(q)) an s-stage PRK method is

    Q_i = q_n + h sum_j a_ij f(P_j)        P_i = p_n + h sum_j ahat_ij g(Q_j)
    q_{n+1} = q_n + h sum_i b_i f(P_i)     p_{n+1} = p_n + h sum_i bhat_i g(Q_i)

Reich (1994), Thm 2.1: the method conserves every bilinear invariant q^T W p (angular momentum) and is
symplectic if (6) B Ahat + A^T Bhat - b bhat^T = 0 and (7) b = bhat.  For separable H, (6) alone
gives symplecticity and conservation of angular momentum (docs/theory.md, section 1).
"""
from __future__ import annotations

from fractions import Fraction
from functools import cached_property
from typing import Sequence

import numpy as np

from .splitting import DRIFT, KICK, Splitting, exact, to_dtype
from ..support.errors import InputError

#: residual of (6) below which a tableau counts as symplectic (float64 data)
SYMPLECTIC_TOL = 1e-12


class TableauError(InputError):
    """A tableau that is malformed, inconsistent or not symplectic."""


def _matrix(name, value, dtype):
    try:
        arr = np.array(value, dtype=dtype)
    except (TypeError, ValueError) as exc:
        raise TableauError(f"{name} must be a square matrix of numbers, got {value!r} ({exc})") from None
    return arr


def _as_array(name, value, dtype):
    if isinstance(value, np.ndarray) and value.dtype.kind in "fiu":
        return value.astype(dtype)
    # Allow exact strings / Fractions element by element.
    try:
        nested = np.array(value, dtype=object)
    except (TypeError, ValueError):
        return _matrix(name, value, dtype)
    conv = np.vectorize(lambda x: to_dtype(exact(x), dtype), otypes=[dtype])
    try:
        return conv(nested) if nested.size else nested.astype(dtype)
    except (TypeError, ValueError) as exc:
        raise TableauError(f"{name} contains a value that is not a number: {exc}") from None


class PRKTableau:
    """A validated PRK tableau pair (A, b) for positions and (A_hat, b_hat) for momenta.

    Entries may be numbers, decimal strings or Fractions; ``dtype`` (float64 or long double) is the
    precision the arrays are stored in.  Construction checks shapes, finiteness and consistency
    (sum b = sum b_hat = 1); symplecticity is *reported* (:attr:`residual_6`, :attr:`residual_7`)
    and enforced by the integrators, which refuse a non-symplectic pair unless told otherwise.

    A tableau is immutable (read-only arrays, no attribute can be set after construction), so its derived
    facts (residuals, explicit order, splitting form) are computed once, on first use, and kept; two
    tableaux with the same arrays and precision are equal and hash alike, whatever their names.
    """

    def __init__(self, A, b, A_hat, b_hat, name: str | None = None, dtype=np.float64):
        init = object.__setattr__
        init(self, "name", name or "user tableau")
        init(self, "dtype", np.dtype(dtype))
        for label, value in (("A", A), ("b", b), ("A_hat", A_hat), ("b_hat", b_hat)):
            arr = _as_array(label, value, dtype)
            arr = np.array(arr, dtype=arr.dtype, copy=True)  # never a view of the caller's array
            arr.setflags(write=False)
            init(self, label, arr)
        self._validate()

    def __setattr__(self, name, value):
        raise AttributeError(f"a PRKTableau is immutable: cannot set {name!r} (build a new PRKTableau instead)")

    def __delattr__(self, name):
        raise AttributeError(f"a PRKTableau is immutable: cannot delete {name!r}")

    def __eq__(self, other):
        if not isinstance(other, PRKTableau):
            return NotImplemented
        return self.dtype == other.dtype and all(
            np.array_equal(getattr(self, k), getattr(other, k)) for k in ("A", "b", "A_hat", "b_hat"))

    def __hash__(self):
        return hash((str(self.dtype),) + tuple(getattr(self, k).tobytes() for k in ("A", "b", "A_hat", "b_hat")))

    def __reduce__(self):
        return (PRKTableau, (self.A, self.b, self.A_hat, self.b_hat, self.name, self.dtype))

    # -- validation ---------------------------------------------------------------------
    def _validate(self):
        b, bh = self.b, self.b_hat
        if b.ndim != 1 or b.size == 0:
            raise TableauError(f"{self.name}: b must be a non-empty vector, got shape {b.shape}")
        s = b.size
        for label, arr, want in (("A", self.A, (s, s)), ("A_hat", self.A_hat, (s, s)), ("b_hat", bh, (s,))):
            if arr.shape != want:
                raise TableauError(
                    f"{self.name}: {label} has shape {arr.shape}, but b has {s} stages so {label} "
                    f"must have shape {want}")
        for label, arr in (("A", self.A), ("b", b), ("A_hat", self.A_hat), ("b_hat", bh)):
            if not np.all(np.isfinite(arr.astype(np.float64))):
                raise TableauError(f"{self.name}: {label} contains non-finite values: {arr.tolist()}")
        tol = 1e-12
        for label, arr in (("b", b), ("b_hat", bh)):
            total = float(np.sum(arr))
            if abs(total - 1.0) > tol:
                raise TableauError(
                    f"{self.name}: the weights {label} sum to {total!r}; a consistent method needs "
                    f"sum({label}) = 1")

    # -- properties ---------------------------------------------------------------------
    @property
    def stages(self) -> int:
        return self.b.size

    @cached_property
    def evaluated_stages(self) -> tuple:
        """Per stage, whether its force is used: by a stage (A_hat column) or by the update (b_hat).  An explicit
        pair evaluates only these; the compiler and :attr:`force_evaluations` read it."""
        Ah, bh = np.asarray(self.A_hat, dtype=np.float64), np.asarray(self.b_hat, dtype=np.float64)
        return tuple(bool(np.any(Ah[:, i]) or bh[i]) for i in range(self.stages))

    @property
    def force_evaluations(self) -> int:
        """Force evaluations per step: the evaluated stages of an explicit pair; every stage of an implicit one
        (per fixed-point iteration)."""
        return sum(self.evaluated_stages) if self.is_explicit else self.stages

    def symplectic_residual_matrix(self):
        """B A_hat + A^T B_hat - b b_hat^T (Reich's condition (6))."""
        return np.diag(self.b) @ self.A_hat + self.A.T @ np.diag(self.b_hat) - np.outer(self.b, self.b_hat)

    @cached_property
    def residual_6(self) -> float:
        """max |B A_hat + A^T B_hat - b b_hat^T|: zero for a symplectic PRK method."""
        return float(np.max(np.abs(self.symplectic_residual_matrix())))

    @cached_property
    def residual_7(self) -> float:
        """max |b - b_hat|: zero is also needed for non-separable H (not for MD)."""
        return float(np.max(np.abs(self.b - self.b_hat)))

    @cached_property
    def is_symplectic(self) -> bool:
        """Symplectic (and angular-momentum conserving) for separable H: condition (6)."""
        return self.residual_6 <= SYMPLECTIC_TOL

    @cached_property
    def is_symplectic_general(self) -> bool:
        """Conditions (6) and (7): symplectic for any H."""
        return self.is_symplectic and self.residual_7 <= SYMPLECTIC_TOL

    @cached_property
    def explicit_order(self):
        """'q-first' if Q_i needs only P_j, j < i (A strictly lower, A_hat lower); 'p-first' for the
        mirror case; None for an implicit pair."""
        A, Ah = self.A, self.A_hat
        if not np.any(np.triu(A)) and not np.any(np.triu(Ah, 1)):
            return "q-first"
        if not np.any(np.triu(Ah)) and not np.any(np.triu(A, 1)):
            return "p-first"
        return None

    @property
    def is_explicit(self) -> bool:
        return self.explicit_order is not None

    def check_symplectic(self, allow_nonsymplectic: bool = False):
        """Raise :class:`TableauError` naming the residual unless condition (6) holds."""
        if not self.is_symplectic and not allow_nonsymplectic:
            raise TableauError(
                f"{self.name} is not symplectic: Reich's condition (6) B*A_hat + A^T*B_hat - b*b_hat^T = 0 "
                f"has residual {self.residual_6:.3e} (tolerance {SYMPLECTIC_TOL:g}); condition (7) "
                f"b = b_hat has residual {self.residual_7:.3e}. It will not conserve angular momentum. "
                f"Pass allow_nonsymplectic=True to use it anyway (e.g. as a reference).")

    def summary(self) -> str:
        kind = "explicit" if self.is_explicit else "implicit"
        return (f"{self.name}: {self.stages} stages, {kind}, residual (6) = {self.residual_6:.2e}, "
                f"residual (7) = {self.residual_7:.2e}")

    def __repr__(self):
        return f"PRKTableau({self.summary()})"

    # -- conversions --------------------------------------------------------------------
    @classmethod
    def from_splitting(cls, splitting: Splitting | Sequence, name=None, dtype=np.float64) -> "PRKTableau":
        """PRK form of a kick/drift sequence (docs/theory.md, section 1).

        The sequence is padded to pairs K(beta_1) D(alpha_1) ... K(beta_s) D(alpha_s); then
        A[i,j] = alpha_j (j < i), b = alpha, A_hat[i,j] = beta_j (j <= i), b_hat = beta."""
        if not isinstance(splitting, Splitting):
            splitting = Splitting(splitting)
        _check_labels(splitting)
        betas, alphas = [], []
        expect = KICK
        for label, c in splitting.steps:
            if label != expect:
                (betas if expect == KICK else alphas).append(Fraction(0))
            (betas if label == KICK else alphas).append(c)
            expect = DRIFT if label == KICK else KICK
        if len(alphas) < len(betas):
            alphas.append(Fraction(0))
        s = len(betas)
        A = [[alphas[j] if j < i else Fraction(0) for j in range(s)] for i in range(s)]
        Ah = [[betas[j] if j <= i else Fraction(0) for j in range(s)] for i in range(s)]
        return cls(A, alphas, Ah, betas, name=name, dtype=dtype)

    @cached_property
    def splitting(self) -> Splitting | None:
        """The kick/drift sequence of a tableau in splitting form, None for any other pair (computed once)."""
        try:
            return self.to_splitting()
        except TableauError:
            return None

    def to_splitting(self, tol: float = 1e-14) -> Splitting:
        """The kick/drift sequence of a tableau in splitting form; TableauError otherwise."""
        s = self.stages
        A, Ah, b, bh = (np.asarray(x, dtype=np.float64) for x in (self.A, self.A_hat, self.b, self.b_hat))
        want_A = np.tril(np.tile(b, (s, 1)), -1)
        want_Ah = np.tril(np.tile(bh, (s, 1)))
        if np.max(np.abs(A - want_A)) > tol or np.max(np.abs(Ah - want_Ah)) > tol:
            raise TableauError(
                f"{self.name} is not a kick/drift splitting: it needs A[i,j] = b[j] for j < i (else 0) "
                f"and A_hat[i,j] = b_hat[j] for j <= i (else 0)")
        seq = []
        for beta, alpha in zip(self.b_hat, self.b):
            seq += [(KICK, exact(float(beta))), (DRIFT, exact(float(alpha)))]
        return Splitting(seq)

    def compose(self, weights: Sequence) -> "PRKTableau":
        """The composition step(w_1 h) o ... o step(w_m h) as one (m*s)-stage PRK tableau pair."""
        w = np.array([to_dtype(exact(x), self.dtype) for x in weights], dtype=self.dtype)
        if w.size == 0:
            raise TableauError("composition weights must not be empty")
        if abs(float(w.sum()) - 1.0) > 1e-14:
            raise TableauError(f"composition weights must sum to 1, got {float(w.sum())!r}")
        s, m = self.stages, w.size

        def block(Am, bm):
            big = np.zeros((m * s, m * s), dtype=self.dtype)
            for k in range(m):
                for l in range(k):
                    big[k * s:(k + 1) * s, l * s:(l + 1) * s] = w[l] * bm[None, :]
                big[k * s:(k + 1) * s, k * s:(k + 1) * s] = w[k] * Am
            return big, np.concatenate([wk * bm for wk in w])

        A, b = block(self.A, self.b)
        Ah, bh = block(self.A_hat, self.b_hat)
        return PRKTableau(A, b, Ah, bh, name=f"{self.name} composed with {m} weights", dtype=self.dtype)


def _check_labels(splitting: Splitting):
    bad = sorted(set(splitting.labels) - {KICK, DRIFT})
    if bad:
        raise TableauError(f"a kick/drift splitting has only 'kick' and 'drift' sub-flows, got {bad}")
