"""Self-diffusion of the waters' centres of mass on any Universe (:class:`SelfDiffusion`)."""
from __future__ import annotations

import numpy as np

from .. import diffusion
from ..molecules import centre_of_mass_trajectory
from .base import ANGSTROM_IN_NM, WaterFrames
from ...support.errors import InputError

__all__ = ["SelfDiffusion"]

#: D's unit: 1e-5 cm^2/s (= 1e-9 m^2/s = 0.1 Angstrom^2/ps), the literature's for water.
D_UNIT = "1e-5 cm^2/s"


class SelfDiffusion(WaterFrames):
    """Self-diffusion coefficient of the waters' centres of mass, in 1e-5 cm^2/s (the unit of water's literature;
    0.1 Angstrom^2/ps), with its standard error.

    Each frame's molecules are made whole, their centres of mass unwrapped across the box
    (:func:`~openmm_symprk.analysis.diffusion.unwrap`: frames must be stored often enough that no molecule moves
    0.4 of an edge between them), the common centre's motion taken out (``drift``), the MSD computed by FFT over
    every time origin and D = slope / 6 fitted over ``window_ps`` (t_min, t_max) ps, default (T/10, T/2) of the
    analysed time T (:func:`~openmm_symprk.analysis.diffusion.self_diffusion`; ``max_lag``: the longest lag,
    frames).  D's standard error (``error="blocks"``, the default) comes from ``n_blocks`` (default 5)
    consecutive blocks of the frames, the window fitted in each
    (:func:`~openmm_symprk.analysis.diffusion.block_error`), which counts the correlations between molecules;
    it is given only where the window ends by half a block (T/10 with 5 blocks: not for the default window),
    else ``se`` is nan and ``se_note`` says why and what would give one.  ``error="molecules"``: the scatter of
    the molecules' own fits, which treats them as independent and understates D's error 2-3x in water.  With
    ``viscosity_mpas`` (mPa s) and
    ``temperature_k`` (K) the Yeh-Hummer finite-size correction of a cubic box is added to give
    ``results.D_infinite``.  Without a box in the trajectory the positions must be continuous: centres of mass
    that jump by about the system's width between frames (positions wrapped into a box the file does not
    store) are refused (:func:`~openmm_symprk.analysis.universe.checks.wrapped_problem`).

    Results, in MDAnalysis' units (Angstrom, ps) and, where :class:`MDAnalysis.analysis.msd.EinsteinMSD` computes
    the same, its names: ``timeseries`` (Angstrom^2, the MSD averaged over molecules at lags ``lag_ps``),
    ``msds_by_particle`` (Angstrom^2, (lags, molecules)); ``D``, ``se``, ``correction``, ``D_infinite`` (nan
    without a viscosity), all in 1e-5 cm^2/s; ``se_note`` (None, or why ``se`` is nan); ``window_ps`` (the lags
    fitted, ps), ``error`` and ``n_samples`` (the molecules or blocks the error came from); ``units`` names each
    result's unit.
    """

    def __init__(self, atomgroup, window_ps=None, *, error: str = "blocks", n_blocks: int = diffusion.ERROR_BLOCKS,
                 drift: bool = True, max_lag: int | None = None, viscosity_mpas: float | None = None,
                 temperature_k: float | None = None, masses=None, **kwargs):
        super().__init__(atomgroup, masses=masses, **kwargs)
        if error not in ("blocks", "molecules"):
            raise InputError(f"error must be 'blocks' or 'molecules', got {error!r}")
        if (viscosity_mpas is None) != (temperature_k is None):
            raise InputError("the Yeh-Hummer correction needs both viscosity_mpas and temperature_k")
        self._options = dict(window_ps=window_ps, error=error, n_blocks=n_blocks, drift=drift, max_lag=max_lag)
        self._eta, self._temperature = viscosity_mpas, temperature_k

    _needs_continuous = True

    def _analyse(self, x, v, box):
        w = self.waters
        dt = self.frame_interval_ps()
        com = centre_of_mass_trajectory(x, w.masses, w.molecules, box)
        if box is not None:
            com = diffusion.unwrap(com, box)
        o = self._options
        window = o["window_ps"]
        if window is None:
            longest = (len(com) - 1) * dt if o["max_lag"] is None else o["max_lag"] * dt
            longest = min(longest, (len(com) // 2) * dt)
            window = (0.2 * longest, longest)
        mol_mass = w.masses[w.molecules].sum(axis=1)
        fit = diffusion.self_diffusion(com, dt, window, error="molecules", max_lag=o["max_lag"], drift=o["drift"],
                                       weights=mol_mass)
        r = self.results
        nm2 = 1.0 / ANGSTROM_IN_NM**2
        r.D, r.se, r.se_note, r.window_ps, r.error = fit.D, fit.se, None, fit.window_ps, o["error"]
        r.n_samples = fit.n_samples
        if o["error"] == "blocks":
            r.n_samples = o["n_blocks"]
            try:
                r.se = diffusion.block_error(com, dt, fit.window_ps, n_blocks=o["n_blocks"], drift=o["drift"],
                                             weights=mol_mass)
            except ValueError as exc:
                r.se, r.se_note = float("nan"), str(exc)
        r.lag_ps, r.timeseries, r.msds_by_particle = fit.lag_ps, fit.msd * nm2, fit.msds * nm2
        r.correction = r.D_infinite = float("nan")
        r.units = {"D": D_UNIT, "se": D_UNIT, "D_infinite": D_UNIT, "correction": D_UNIT,
                   "timeseries": "Angstrom^2", "msds_by_particle": "Angstrom^2", "lag_ps": "ps", "window_ps": "ps"}
        if self._eta is not None:
            if box is None:
                raise InputError("the Yeh-Hummer correction needs the box: the trajectory has none")
            edge = box.mean(axis=0)
            if np.ptp(edge) > 0.01 * edge.mean():
                raise InputError(f"the Yeh-Hummer correction here is for a cubic box; the mean edges are "
                                 f"{np.round(edge / ANGSTROM_IN_NM, 3).tolist()} Angstrom")
            r.correction = diffusion.yeh_hummer(float(edge.mean()), self._temperature, self._eta)
            r.D_infinite = fit.D + r.correction
