"""Angular velocity of molecules and its autocorrelation (pure numpy).  Units: nm, ps, Da; omega in rad/ps.

Each molecule's angular velocity is omega = I^-1 L, with L its angular momentum and I its inertia tensor
about its own centre of mass, from positions, velocities and masses through the package's one definition of
a molecule's centre-of-mass frame (:func:`openmm_symprk.physics.momenta.molecule_frames`).  For a rigid
molecule it is the exact rotation rate (v_i = V + omega x r_i); for a flexible one it is the rate that
carries the angular momentum; a linear molecule's has no component along its axis.

``frame="space"``: components along the box axes.  ``frame="body"``: along the molecule's principal axes
e_1, e_2, e_3 (moments ascending), each axis's sign fixed from the molecule's atoms (e_1, e_2 point towards
the side of the first atom, in the molecule's order, that lies off the plane normal to them by more than
1e-6 nm) and e_3 = e_1 x e_2; a molecule with two equal moments (symmetric or linear top) has no unique
body frame and is refused.  For water (O, H, H) e_1 is the H-H direction, e_2 the symmetry axis and e_3
the normal to the molecular plane.

The normalised autocorrelation (Asthagiri & Beck, J. Chem. Theory Comput. 2024, arXiv 2308.08383):

    C(t) = < omega(t0) . omega(t0 + t) > / < omega . omega >

averaged over molecules and time origins (:func:`angular_velocity_acf`; per component in the body frame
with ``components=True``).  Its summary (:func:`acf_summary`): the first zero crossing, the first local
minimum (time and value) and the trapezoidal integral of C from 0 to the last computed lag (ps; it
oscillates with the librations, so the integral is stated together with its upper limit).
:func:`omega_correlation` gives both, with the summary's standard errors from the delete-one-group
jackknife over groups of molecules (:func:`openmm_symprk.stats.jackknife`).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..stats import jackknife
from .correlation import origin_averaged_correlation
from ..support import InputError, require
from .molecules import make_whole, molecule_index, trajectory_frames

__all__ = ["angular_velocities", "angular_velocity_acf", "AcfSummary", "acf_summary", "first_zero", "first_minimum",
           "omega_correlation"]

_SIGN_TOL_NM = 1e-6
_LINEAR = 1e-8  # smallest / largest principal moment below which a molecule is linear
_DEGENERATE = 1e-6  # relative gap between principal moments below which the body frame is not unique


def _body_axes(inertia, r):
    """Principal axes (..., 3, 3) as columns e_1, e_2, e_3 with the signs fixed from the atoms r (..., k, 3)."""
    moments, axes = np.linalg.eigh(inertia)
    gap = np.minimum(moments[..., 1] - moments[..., 0], moments[..., 2] - moments[..., 1])
    if np.any(gap <= _DEGENERATE * moments[..., 2]):
        raise InputError("a molecule has two equal principal moments (a symmetric or linear top): its body "
                         "frame is not unique; use frame='space'")
    for a in (0, 1):
        proj = np.einsum("...kd,...d->...k", r, axes[..., :, a])
        first = np.argmax(np.abs(proj) > _SIGN_TOL_NM, axis=-1)
        sign = np.sign(np.take_along_axis(proj, first[..., None], axis=-1)[..., 0])
        axes[..., :, a] *= np.where(sign == 0, 1.0, sign)[..., None]
    axes[..., :, 2] = np.cross(axes[..., :, 0], axes[..., :, 1])
    return axes


def angular_velocities(x, v, m, molecules, frame: str = "space", box=None) -> np.ndarray:
    """Angular velocity (F, n, 3) rad/ps of each molecule at each frame, about its centre of mass, from
    positions ``x`` (F, N, 3) nm (molecules whole, or made whole in the orthorhombic ``box``: 3 edges nm or
    (F, 3)), velocities ``v`` (F, N, 3) nm/ps and masses ``m`` (N,) Da; components in the ``frame`` "space"
    or "body" (see the module docstring)."""
    if frame not in ("space", "body"):
        raise InputError(f"frame must be 'space' or 'body', got {frame!r}")
    if box is not None:
        x = np.array(x, dtype=np.float64)
        x[:, molecule_index(molecules)] = make_whole(x, molecules, box)
    fr = trajectory_frames(x, v, m, molecules)
    if np.any(fr.M <= 0):
        raise InputError("a molecule has no mass: no angular velocity")
    # pseudo-inverse: a linear molecule has no rotation about its axis (as physics.temperature counts it)
    omega = np.einsum("...ij,...j->...i", np.linalg.pinv(fr.inertia, rcond=_LINEAR, hermitian=True), fr.L)
    if frame == "body":
        omega = np.einsum("...dj,...d->...j", _body_axes(fr.inertia, fr.r), omega)
    return omega


def angular_velocity_acf(omega, max_lag: int | None = None, components: bool = False) -> np.ndarray:
    """Normalised autocorrelation of ``omega`` (F, n, 3) at lags 0..max_lag frames (default half the
    trajectory), averaged over molecules and time origins: (max_lag + 1,) for omega(t0) . omega(t0 + t) /
    <|omega|^2>, or (max_lag + 1, 3) per component with ``components=True`` (each normalised by its own
    mean square)."""
    omega = np.asarray(omega, dtype=np.float64)
    if omega.ndim != 3 or omega.shape[2] != 3:
        raise InputError(f"omega must have shape (n_frames, n_molecules, 3) in rad/ps, got {omega.shape}")
    c = origin_averaged_correlation(omega, max_lag).mean(axis=1)  # (L, 3)
    if components:
        if np.any(c[0] == 0):
            raise InputError("a component of omega is zero at every frame: it has no normalised autocorrelation")
        return c / c[0]
    total = c.sum(axis=1)
    if total[0] == 0:
        raise InputError("omega is zero at every frame: it has no normalised autocorrelation")
    return total / total[0]


@dataclass
class AcfSummary:
    """First zero crossing (ps, nan if none), first local minimum (ps and value, nan if none) and the
    integral of C from 0 to ``t_max`` (ps); standard errors (nan unless computed: :func:`omega_correlation`).
    The zero and the minimum are read off the curve between its samples (:func:`first_zero`, :func:`first_minimum`),
    not off the sample grid: two runs sampled on different grids (a 4-fs and a 7-fs step) compare."""

    t_zero: float
    t_min: float
    c_min: float
    integral: float
    t_max: float
    t_zero_se: float = float("nan")
    c_min_se: float = float("nan")
    integral_se: float = float("nan")


def acf_summary(c, dt_ps: float) -> AcfSummary:
    """The summary (:class:`AcfSummary`) of a normalised correlation function ``c`` (lags 0, dt, ...)."""
    c = np.asarray(c, dtype=np.float64)
    if c.ndim != 1 or len(c) < 3:
        raise InputError(f"c must be a 1-D correlation function of at least 3 lags, got shape {c.shape}")
    if not dt_ps > 0:
        raise InputError(f"dt_ps must be > 0, got {dt_ps}")
    t_zero = first_zero(c) * dt_ps
    lag, c_min = first_minimum(c)
    integral = float(dt_ps * (c.sum() - 0.5 * (c[0] + c[-1])))
    return AcfSummary(float(t_zero), float(lag * dt_ps), float(c_min), integral, (len(c) - 1) * dt_ps)


def _spline(c):
    CubicSpline = require("scipy.interpolate", "analysis", "the omega ACF's features between samples").CubicSpline
    return CubicSpline(np.arange(len(c), dtype=np.float64), c)


def first_zero(c) -> float:
    """The first downward zero crossing of the sampled curve ``c``, in units of its sampling interval (nan if none):
    the root, between the two samples of the first sign change, of the cubic spline through every sample.  The spline
    follows the curvature a straight line between two samples misses: a libration-like decay sampled every 4, 6 or
    7 fs reads within 0.01 fs of its finely sampled crossing (tests/analysis/test_angular.py)."""
    c = np.asarray(c, dtype=np.float64)
    crossing = np.nonzero((c[:-1] > 0) & (c[1:] <= 0))[0]
    if not len(crossing):
        return float("nan")
    k = int(crossing[0])
    if len(c) < 4:
        return float(k + c[k] / (c[k] - c[k + 1]))
    roots = [r for r in _spline(c).roots(extrapolate=False) if k <= r <= k + 1]
    return float(roots[0]) if roots else float(k + c[k] / (c[k] - c[k + 1]))


def first_minimum(c) -> tuple:
    """(lag, value) of the first local minimum of the sampled curve ``c`` (lag in units of the sampling interval;
    nans if none): the lowest point, within one interval of the first sample lower than both its neighbours, of the
    cubic spline through every sample (on 4-7 fs grids of a libration-like decay: within 0.05 fs and 3e-4 of the
    finely sampled minimum, where the lowest sample can be 0.03 off)."""
    c = np.asarray(c, dtype=np.float64)
    minima = np.nonzero((c[1:-1] < c[:-2]) & (c[1:-1] <= c[2:]))[0]
    if not len(minima):
        return float("nan"), float("nan")
    m = int(minima[0]) + 1
    if len(c) < 4:
        return float(m), float(c[m])
    spline = _spline(c)
    candidates = [r for r in spline.derivative().roots(extrapolate=False) if m - 1 <= r <= m + 1] + [float(m)]
    best = min(candidates, key=lambda r: float(spline(r)))
    return float(best), float(spline(best))


def omega_correlation(omega, dt_ps: float, max_lag: int | None = None, n_groups: int = 20) -> tuple:
    """(C(t) (max_lag + 1,), :class:`AcfSummary` with the standard errors of t_zero, c_min and the integral)
    of the angular velocities ``omega`` (F, n, 3) rad/ps sampled every ``dt_ps``: the normalised
    autocorrelation of :func:`angular_velocity_acf`, summarised by :func:`acf_summary`; errors by the
    delete-one-group jackknife over ``n_groups`` groups of molecules."""
    omega = np.asarray(omega, dtype=np.float64)
    if omega.ndim != 3 or omega.shape[2] != 3:
        raise InputError(f"omega must have shape (n_frames, n_molecules, 3) in rad/ps, got {omega.shape}")
    per = origin_averaged_correlation(omega, max_lag).sum(axis=2)  # (L, n), not normalised
    if not per[0].mean() > 0:
        raise InputError("omega is zero at every frame: it has no normalised autocorrelation")
    c = per.mean(axis=1) / per[0].mean()

    def figures(mean):
        s = acf_summary(mean / mean[0], dt_ps)
        return np.array([s.t_zero, s.c_min, s.integral])

    summary = acf_summary(c, dt_ps)
    _, se = jackknife(per, figures, n_groups)
    summary.t_zero_se, summary.c_min_se, summary.integral_se = (float(e) for e in se)
    return c, summary
