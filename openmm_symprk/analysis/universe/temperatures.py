"""Translational, rotational and internal kinetic temperatures of molecules on any Universe
(:class:`KineticTemperatures`)."""
from __future__ import annotations

import numpy as np

from ...conservation.analysis import group_masses, subgroups
from ...physics.temperature import kinetic_temperatures
from ...stats import block_stats, series_stats
from ...support import require
from .base import ANGSTROM_IN_NM, AnalysisBase, refuse_unknown_keywords
from ...support.errors import InputError

__all__ = ["KineticTemperatures", "WholeMolecules"]

_KEYS = ("translational", "rotational", "internal", "difference")
#: Without bonds, a molecule is made whole from its first atom: a site farther than this fraction of a box edge
#: from it (along an edge) could belong to either image, and the molecule is refused.
WHOLE_LIMIT = 0.4


class WholeMolecules:
    """Molecules (index arrays into ``atomgroup``) made whole across the periodic box, frame by frame, with
    MDAnalysis' own tools: a molecule with bonds inside it (the topology's: PSF, PRMTOP, TPR, a PDB's CONECT, or
    ``guess_bonds=True``) by :func:`MDAnalysis.lib.mdamath.make_whole` along its bonds, when one of them is
    split by the box (any size of molecule); a molecule without bonds (a water from a PDB: every site bonded to
    its first atom, the oxygen) by putting each site at the minimum image of the molecule's first atom
    (:func:`MDAnalysis.lib.distances.minimize_vectors`), which holds for molecules smaller than
    :data:`WHOLE_LIMIT` of the box (ValueError otherwise, asking for bonds).  Any box MDAnalysis takes,
    triclinic included."""

    def __init__(self, atomgroup, molecules):
        distances = require("MDAnalysis.lib.distances", "analysis", "KineticTemperatures")
        self._minimize = distances.minimize_vectors
        mdamath = require("MDAnalysis.lib.mdamath", "analysis", "KineticTemperatures")
        self._make_whole, self._box_vectors = mdamath.make_whole, mdamath.triclinic_vectors
        self._ag = atomgroup
        n = atomgroup.n_atoms
        mol_of = np.full(n, -1)
        for k, g in enumerate(molecules):
            mol_of[np.asarray(g, dtype=int)] = k
        self._molecules = [np.asarray(g, dtype=int) for g in molecules]
        pairs = np.zeros((0, 2), dtype=int)
        if hasattr(atomgroup.universe.atoms, "bonds") and n:
            local = np.full(atomgroup.universe.atoms.n_atoms, -1)
            local[atomgroup.indices] = np.arange(n)
            ix = np.asarray(atomgroup.bonds.indices, dtype=int).reshape(-1, 2)
            pairs = local[ix]
            pairs = pairs[(pairs >= 0).all(axis=1)]
            pairs = pairs[(mol_of[pairs[:, 0]] == mol_of[pairs[:, 1]]) & (mol_of[pairs[:, 0]] >= 0)]
        self._bonds, self._bond_mol = pairs, mol_of[pairs[:, 0]] if len(pairs) else np.zeros(0, dtype=int)
        bonded = np.zeros(len(molecules), dtype=bool)
        bonded[self._bond_mol] = True
        loose = [g for k, g in enumerate(self._molecules) if not bonded[k] and len(g) > 1]
        self._loose = np.concatenate(loose) if loose else np.zeros(0, dtype=int)
        self._anchor = np.concatenate([np.full(len(g), g[0]) for g in loose]) if loose else np.zeros(0, dtype=int)

    def positions(self, x, dimensions) -> np.ndarray:
        """``x`` (the group's positions at this frame, Angstrom) with every molecule whole in the box
        ``dimensions`` (MDAnalysis' [a, b, c, alpha, beta, gamma]); a copy, ``x`` is kept."""
        x = np.array(x, dtype=np.float32)
        box = np.asarray(dimensions, dtype=np.float32)
        if len(self._bonds):
            d = x[self._bonds[:, 1]] - x[self._bonds[:, 0]]
            split = np.abs(self._minimize(d, box) - d).max(axis=1) > 1e-3
            for k in np.unique(self._bond_mol[split]):
                sel = self._molecules[k]
                try:
                    x[sel] = self._make_whole(self._ag[sel], inplace=False)
                except ValueError as exc:  # its bonds do not connect it
                    raise InputError(f"{self._label(sel)} is split across the box and {exc}: give the topology "
                                     f"all its bonds (or guess_bonds=True)") from None
        if len(self._loose):
            d = self._minimize(x[self._loose] - x[self._anchor], box)
            far = (np.abs(d) > WHOLE_LIMIT * np.diag(self._box_vectors(box))).any(axis=1)
            if far.any():
                k = int(np.argmax(far))
                site, first = self._ag[self._loose[k]].index, self._ag[self._anchor[k]].index
                raise InputError(f"atom {site} lies beyond {WHOLE_LIMIT} of a box edge from atom {first}, the first "
                                 f"of {self._label(self._anchor[k])}: without bonds the molecule cannot be made "
                                 f"whole; give the topology its bonds (or guess_bonds=True)")
            x[self._loose] = x[self._anchor] + d
        return x

    def _label(self, sel) -> str:
        a = self._ag[int(np.atleast_1d(sel)[0])]
        return f"the molecule of atom {a.index} (residue {a.resname} {a.resid})"


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
    needs pymbar).  In frames with a box, molecules split across it (atoms wrapped one by one, as most engines
    write them) are made whole first (:class:`WholeMolecules`: along their bonds, or from their first atom);
    without a box they must be whole in the trajectory.  float32 storage limits each value to ~1e-7 relative,
    far below the statistical spread of a kinetic temperature.

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
        self._whole = WholeMolecules(atomgroup, self._sub)
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
        x = self._ag.positions
        dims = self._ts.dimensions
        if dims is not None and np.all(np.asarray(dims[:3]) > 0):
            x = self._whole.positions(x, dims)
        x = x.astype(np.float64) * ANGSTROM_IN_NM
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
