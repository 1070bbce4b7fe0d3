"""Self-diffusion of the waters' centres of mass on any Universe (:class:`SelfDiffusion`)."""
from __future__ import annotations

import numpy as np

from .. import diffusion
from ..molecules import centre_of_mass_trajectory
from .base import WaterFrames

__all__ = ["SelfDiffusion"]


class SelfDiffusion(WaterFrames):
    """Self-diffusion coefficient of the waters' centres of mass, 1e-5 cm^2/s, with its standard error.

    Each frame's molecules are made whole, their centres of mass unwrapped across the box
    (:func:`~openmm_symprk.analysis.diffusion.unwrap`: frames must be stored often enough that no molecule moves
    0.4 of an edge between them), the common centre's motion taken out (``drift``), the MSD computed by FFT over
    every time origin and D = slope / 6 fitted over ``window_ps`` (t_min, t_max) ps, default (T/10, T/2) of the
    analysed time T (:func:`~openmm_symprk.analysis.diffusion.self_diffusion`; ``error``: "molecules" or
    "blocks" with ``n_blocks``).  With ``viscosity_mpas`` and ``temperature_k`` the Yeh-Hummer finite-size
    correction of a cubic box is added to give ``results.D_infinite``.

    Results: ``D``, ``se``, ``fit`` (:class:`~openmm_symprk.analysis.diffusion.DiffusionFit`), ``lag_ps``,
    ``msd`` (nm^2, molecule average), ``window_ps``; ``correction``, ``D_infinite`` (nan without a viscosity).
    """

    def __init__(self, atomgroup, window_ps=None, *, error: str = "molecules", n_blocks: int = 5,
                 drift: bool = True, max_lag: int | None = None, viscosity_mpas: float | None = None,
                 temperature_k: float | None = None, masses=None, **kwargs):
        super().__init__(atomgroup, masses=masses, **kwargs)
        if (viscosity_mpas is None) != (temperature_k is None):
            raise ValueError("the Yeh-Hummer correction needs both viscosity_mpas and temperature_k")
        self._options = dict(window_ps=window_ps, error=error, n_blocks=n_blocks, drift=drift, max_lag=max_lag)
        self._eta, self._temperature = viscosity_mpas, temperature_k

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
        fit = diffusion.self_diffusion(com, dt, window, error=o["error"], n_blocks=o["n_blocks"],
                                       max_lag=o["max_lag"], drift=o["drift"], weights=mol_mass)
        r = self.results
        r.fit, r.D, r.se, r.lag_ps, r.msd, r.window_ps = fit, fit.D, fit.se, fit.lag_ps, fit.msd, fit.window_ps
        r.correction = r.D_infinite = float("nan")
        if self._eta is not None:
            if box is None:
                raise ValueError("the Yeh-Hummer correction needs the box: the trajectory has none")
            edge = box.mean(axis=0)
            if np.ptp(edge) > 0.01 * edge.mean():
                raise ValueError(f"the Yeh-Hummer correction here is for a cubic box; the mean edges are "
                                 f"{np.round(edge, 4).tolist()} nm")
            r.correction = diffusion.yeh_hummer(float(edge.mean()), self._temperature, self._eta)
            r.D_infinite = fit.D + r.correction
