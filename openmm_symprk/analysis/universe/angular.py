"""The angular-velocity autocorrelation of rigid waters on any Universe (:class:`AngularVelocityCorrelation`)."""
from __future__ import annotations

import numpy as np

from .. import angular
from .base import WaterFrames
from ...support.errors import InputError

__all__ = ["AngularVelocityCorrelation"]


class AngularVelocityCorrelation(WaterFrames):
    """The normalised autocorrelation C(t) = <omega(0) . omega(t)> / <omega^2> of the waters' angular
    velocities omega = I^-1 L about their centres of mass (rad/ps; positions and velocities needed), averaged
    over molecules and every time origin (:func:`~openmm_symprk.analysis.angular.omega_correlation`), and its
    summary: first zero, first minimum, integral to the last lag, with jackknife errors over ``n_groups``
    groups of molecules.  ``frame``: "space" or "body" (principal axes); ``max_lag``: the longest lag, frames
    (default half the analysed frames).  The librations live within ~0.1 ps: store frames every few fs.

    Results: ``lag_ps``, ``acf`` (C(t)), ``summary`` (:class:`~openmm_symprk.analysis.angular.AcfSummary`, ps),
    ``omega`` (F, n, 3) rad/ps; ``units``.
    """

    _needs_velocities = True

    def __init__(self, atomgroup, frame: str = "space", *, max_lag: int | None = None, n_groups: int = 20,
                 masses=None, **kwargs):
        super().__init__(atomgroup, masses=masses, **kwargs)
        if frame not in ("space", "body"):
            raise InputError(f"frame must be 'space' or 'body', got {frame!r}")
        self._frame, self._max_lag, self._n_groups = frame, max_lag, n_groups

    def _analyse(self, x, v, box):
        dt = self.frame_interval_ps()
        w = self.waters
        omega = angular.angular_velocities(x, v, w.masses, w.molecules, self._frame, box)
        max_lag = self._max_lag if self._max_lag is not None else max(2, len(omega) // 2)
        acf, summary = angular.omega_correlation(omega, dt, min(max_lag, len(omega) - 1), self._n_groups)
        r = self.results
        r.omega, r.acf, r.summary, r.lag_ps = omega, acf, summary, np.arange(len(acf)) * dt
        r.units = {"lag_ps": "ps", "acf": "", "omega": "rad/ps", "summary.t_zero": "ps", "summary.integral": "ps"}
