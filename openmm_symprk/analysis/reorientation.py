"""Reorientation of molecules: Legendre correlation functions of a molecule-fixed unit vector and their
correlation times (pure numpy).  Units: nm, ps.

    C_l(t) = < P_l(u(t0) . u(t0 + t)) >,   P_1(x) = x,   P_2(x) = (3 x^2 - 1) / 2,

averaged over molecules and every time origin t0 (by FFT: P_1 is the sum of the 3 components' correlations,
P_2 uses (u.u')^2 = sum_ab u_a u_b u'_a u'_b, the correlations of the 6 products u_a u_b).  For rotational
diffusion with constant D_r, C_l(t) = exp(-l (l + 1) D_r t), so tau_1 = 1 / (2 D_r) and tau_2 = 1 / (6 D_r).

Correlation time (:func:`correlation_time`): tau = integral_0^inf C_l(t) dt, computed as the trapezoidal
integral of the measured C_l from 0 to the cutoff t_c, the first lag where C_l <= ``c_cut`` (default 0.1;
the last lag if it never gets there), plus the integral of an exponential tail A exp(-t / tau_e) from t_c
to infinity, A and tau_e fitted (least squares on log C_l) to the measured C_l over the lags where
``c_cut`` <= C_l <= ``c_fit`` (default 0.5) up to t_c.  The fast librational drop of water at t < 0.1 ps
lies above C = 0.5 and is integrated, not fitted.  Its standard error (:func:`reorientation_time`): the
delete-one-group jackknife over ``n_groups`` disjoint groups of molecules (tau is a non-linear function of
C_l, which the jackknife handles better than the scatter of small groups' own tau).

Vectors (:func:`dipole_vectors`, :func:`atom_vectors`, :func:`bisector_vectors`): from positions of whole
molecules (or pass ``box`` to make each whole by the minimum image from its first atom).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..stats import jackknife
from .correlation import origin_averaged_correlation
from .molecules import make_whole, molecule_index
from ..support.errors import InputError

__all__ = ["atom_vectors", "bisector_vectors", "dipole_vectors", "legendre_correlation", "correlation_time",
           "CorrelationTime", "reorientation_time", "molecules_correlation_time"]


def _positions(x, molecules, box):
    """(F, n, k, 3) positions of the molecules' atoms, made whole from the first atom when ``box`` is given."""
    return make_whole(x, molecules, box)


def _unit(u):
    norm = np.linalg.norm(u, axis=-1, keepdims=True)
    if np.any(norm == 0):
        raise InputError("a molecule's vector has zero length (coincident atoms, or a molecule without dipole)")
    return u / norm


def atom_vectors(x, molecules, i: int, j: int, box=None) -> np.ndarray:
    """Unit vectors (F, n, 3) from atom ``i`` to atom ``j`` of each molecule (positions in the molecule's
    index list), e.g. the H-H vector of water (O, H, H) with i=1, j=2."""
    xg = _positions(x, molecules, box)
    return _unit(xg[:, :, j] - xg[:, :, i])


def bisector_vectors(x, molecules, apex: int = 0, ends=(1, 2), box=None) -> np.ndarray:
    """Unit vectors (F, n, 3) from the ``apex`` atom (water's O) to the midpoint of the two ``ends`` (the
    H atoms): water's symmetry axis, along which a 3- or 4-site water's dipole lies."""
    xg = _positions(x, molecules, box)
    return _unit(0.5 * (xg[:, :, ends[0]] + xg[:, :, ends[1]]) - xg[:, :, apex])


def dipole_vectors(x, molecules, charges, box=None) -> np.ndarray:
    """Unit dipole vectors (F, n, 3) sum_i q_i x_i of neutral molecules (``charges``: one per atom of the
    system, e; a charged molecule's dipole depends on the origin, so it is refused)."""
    idx = molecule_index(molecules)
    q = np.asarray(charges, dtype=np.float64)[idx]
    net = np.abs(q.sum(axis=1)).max()
    if net > 1e-6:
        raise InputError(f"a molecule carries a net charge of {net:.3g} e: its dipole depends on the origin; "
                         f"use atom_vectors or bisector_vectors for charged molecules")
    xg = _positions(x, molecules, box)
    return _unit(np.einsum("nk,fnkd->fnd", q, xg))


def legendre_correlation(u, order: int, max_lag: int | None = None) -> np.ndarray:
    """C_l at lags 0..max_lag frames (default half the trajectory) of each molecule, shape (max_lag + 1, n),
    from unit vectors ``u`` (F, n, 3), averaged over time origins (average over axis 1 for the molecules)."""
    u = np.asarray(u, dtype=np.float64)
    if u.ndim != 3 or u.shape[2] != 3:
        raise InputError(f"u must have shape (n_frames, n_molecules, 3), got {u.shape}")
    if order == 1:
        return origin_averaged_correlation(u, max_lag).sum(axis=2)
    if order == 2:
        a, b = np.triu_indices(3)
        products = u[..., a] * u[..., b]  # (F, n, 6): xx xy xz yy yz zz
        weight = np.where(a == b, 1.0, 2.0)
        cos2 = (origin_averaged_correlation(products, max_lag) * weight).sum(axis=2)
        return 1.5 * cos2 - 0.5
    raise InputError(f"order must be 1 or 2 (first or second Legendre polynomial), got {order}")


@dataclass
class CorrelationTime:
    """tau (ps) = integral (to t_cut) + tail (from t_cut, exponential with time constant tau_exp)."""

    tau: float
    se: float
    integral: float
    tail: float
    tau_exp: float
    t_cut: float

    def __format__(self, spec):
        spec = spec or ".3f"
        return f"{format(self.tau, spec)} ± {format(self.se, spec)}"


def correlation_time(c, dt_ps: float, c_cut: float = 0.1, c_fit: float = 0.5) -> CorrelationTime:
    """The correlation time (ps) of a decaying correlation function ``c`` (lags 0, dt, 2 dt ..., c[0] = 1),
    as the module docstring states: trapezoid to t_cut, exponential tail beyond it (se left at nan)."""
    c = np.asarray(c, dtype=np.float64)
    if not dt_ps > 0:
        raise InputError(f"dt_ps must be > 0, got {dt_ps}")
    if not 0 < c_cut < c_fit < 1:
        raise InputError(f"need 0 < c_cut < c_fit < 1, got c_cut={c_cut}, c_fit={c_fit}")
    below = np.nonzero(c <= c_cut)[0]
    cut = int(below[0]) if len(below) else len(c) - 1
    fit = np.nonzero((c[:cut + 1] >= c_cut) & (c[:cut + 1] <= c_fit))[0]
    if len(fit) < 3:
        raise InputError(f"the correlation function has fewer than 3 lags between C = {c_fit} and C = {c_cut} "
                         f"(it ends at C = {c[-1]:.3g} after {(len(c) - 1) * dt_ps:g} ps, or decays within a "
                         f"frame): store frames more often or run longer")
    t = np.arange(len(c)) * dt_ps
    slope, intercept = np.polyfit(t[fit], np.log(c[fit]), 1)
    if not slope < 0:
        raise InputError(f"the correlation function does not decay between C = {c_fit} and C = {c_cut}")
    tau_exp = -1.0 / slope
    integral = float(dt_ps * (c[:cut + 1].sum() - 0.5 * (c[0] + c[cut])))  # trapezoid
    tail = float(np.exp(intercept - t[cut] / tau_exp) * tau_exp)
    return CorrelationTime(integral + tail, float("nan"), integral, tail, float(tau_exp), float(t[cut]))


def reorientation_time(u, order: int, dt_ps: float, *, n_groups: int = 20, max_lag: int | None = None,
                       c_cut: float = 0.1, c_fit: float = 0.5) -> tuple:
    """(C_l averaged over molecules (max_lag + 1,), :class:`CorrelationTime` tau_l in ps with its standard
    error) for unit vectors ``u`` (F, n, 3) every ``dt_ps``.  The error is the delete-one-group jackknife over
    ``n_groups`` disjoint groups of molecules (:func:`openmm_symprk.stats.jackknife`)."""
    c = legendre_correlation(u, order, max_lag)
    return c.mean(axis=1), molecules_correlation_time(c, dt_ps, n_groups=n_groups, c_cut=c_cut, c_fit=c_fit)


def molecules_correlation_time(c, dt_ps: float, *, n_groups: int = 20, c_cut: float = 0.1,
                               c_fit: float = 0.5) -> CorrelationTime:
    """:class:`CorrelationTime` of the molecule average of ``c`` (L, n), one correlation function per molecule
    (from :func:`legendre_correlation`), with its jackknife error over ``n_groups`` groups of molecules."""
    result = correlation_time(np.asarray(c).mean(axis=1), dt_ps, c_cut, c_fit)
    _, result.se = jackknife(c, lambda m: correlation_time(m, dt_ps, c_cut, c_fit).tau, n_groups)
    return result
