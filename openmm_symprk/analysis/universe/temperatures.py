"""Translational, rotational and internal kinetic temperatures of molecules on any Universe
(:class:`KineticTemperatures`)."""
from __future__ import annotations

import numpy as np

from ...conservation.analysis import group_masses, subgroups
from ...physics.temperature import kinetic_temperatures
from ...stats import block_stats, series_stats
from .base import ANGSTROM_IN_NM, AnalysisBase, refuse_unknown_keywords
from ...support.errors import InputError

__all__ = ["KineticTemperatures"]

_KEYS = ("translational", "rotational", "internal", "difference")


class KineticTemperatures(AnalysisBase):
    """Translational, rotational and internal kinetic temperature (K) of the molecules per frame
    (:func:`openmm_symprk.physics.temperature.kinetic_temperatures`), and their means with standard errors.

    Molecules are the group's ``fragments`` (bonded components; :func:`openmm_symprk.conservation.analysis.universe`
    gives them bonds), or its ``residues`` with ``by="residues"``.  ``momentum_fixed`` (default True): the run
    conserved or removed the total momentum, so translation has 3 N_mol - 3 degrees of freedom; ``constraints``:
    the number of distance constraints inside the molecules (pass the ``openmm.System`` as ``masses=`` and it
    is taken from there).  Errors: from ``n_blocks`` consecutive block means
    (:func:`openmm_symprk.stats.block_stats`; default 10, fewer for short trajectories, at least 2 frames per
    block), or with ``n_blocks=None`` from the statistical inefficiency (:func:`openmm_symprk.stats.series_stats`,
    needs pymbar).  Molecules must be whole in the trajectory; float32 storage limits each value to ~1e-7
    relative, far below the statistical spread of a kinetic temperature.

    Results: ``translational``, ``rotational``, ``internal``, ``difference`` (rotational - translational), one
    value per frame; ``mean_translational`` ... their means and ``se_translational`` ... their standard errors
    (nan with fewer than 4 frames); ``dof``; ``units`` (K for all).
    """

    def __init__(self, atomgroup, masses=None, by: str = "fragments", momentum_fixed: bool = True,
                 constraints: int | None = None, n_blocks: int | None = 10, verbose: bool = False, **kwargs):
        refuse_unknown_keywords(self, kwargs)
        atomgroup = getattr(atomgroup, "atoms", atomgroup)
        super().__init__(atomgroup.universe.trajectory, verbose=verbose)
        self._ag = atomgroup
        self._m = group_masses(atomgroup, masses)
        if by not in ("residues", "fragments", "segments"):
            raise InputError(f"by must be 'residues', 'fragments' or 'segments', got {by!r}")
        self._sub = [list(g) for g in subgroups(atomgroup, by)]
        self._fixed = momentum_fixed
        if constraints is None and hasattr(masses, "getNumConstraints"):
            constraints = masses.getNumConstraints()
        self._constraints = constraints or 0
        if n_blocks is not None and (int(n_blocks) != n_blocks or n_blocks < 2):
            raise InputError(f"n_blocks must be an integer >= 2 or None, got {n_blocks!r}")
        self._n_blocks = n_blocks

    def _prepare(self):
        for key in _KEYS:
            self.results[key] = np.zeros(self.n_frames)

    def _single_frame(self):
        if not self._ts.has_velocities:
            raise InputError(f"KineticTemperatures needs velocities and frame {self._ts.frame} of the trajectory "
                             f"has none (DCD, XTC and PDB store positions only: use a TRR, NetCDF or H5MD "
                             f"trajectory written with velocities)")
        x = self._ag.positions.astype(np.float64) * ANGSTROM_IN_NM
        v = self._ag.velocities.astype(np.float64) * ANGSTROM_IN_NM
        t = kinetic_temperatures(x, v, self._m, self._sub, self._fixed, self._constraints)
        i = self._frame_index
        self.results.translational[i], self.results.rotational[i] = t.translational, t.rotational
        self.results.internal[i], self.results.difference[i] = t.internal, t.difference
        self.results.dof = {"translational": t.translational_dof, "rotational": t.rotational_dof,
                            "internal": t.internal_dof}

    def _conclude(self):
        dt = float(np.median(np.diff(self.times))) if self.n_frames > 1 else 1.0
        for key in _KEYS:
            series = self.results[key]
            self.results[f"mean_{key}"] = float(np.mean(series)) if self.n_frames else float("nan")
            se = float("nan")
            if self.n_frames >= 4 and np.all(np.isfinite(series)):
                if self._n_blocks is None:
                    se = series_stats(series, dt).se
                else:
                    se = block_stats(series, min(int(self._n_blocks), self.n_frames // 2), dt).se
            self.results[f"se_{key}"] = se
        self.results.units = {key: "K" for key in self.results if key not in ("dof",)}
