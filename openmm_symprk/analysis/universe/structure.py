"""The O-O radial distribution function of the waters on any Universe (:class:`RadialDistribution`)."""
from __future__ import annotations

import numpy as np

from .. import structure
from .base import ANGSTROM_IN_NM, WaterFrames
from ...support.errors import InputError

__all__ = ["RadialDistribution"]

#: The default bin width, Angstrom.
BIN_WIDTH = 0.05


class RadialDistribution(WaterFrames):
    """g(r) of the waters' oxygens (:func:`~openmm_symprk.analysis.structure.radial_distribution`: MDAnalysis'
    InterRDF in ``n_blocks`` blocks of frames) in ``nbins`` bins over ``range`` = (0, r_max) Angstrom, as
    :class:`MDAnalysis.analysis.rdf.InterRDF` takes them (defaults: r_max half the shortest box edge, bins of
    :data:`BIN_WIDTH` Angstrom), and its first peak beyond ``peak_from`` Angstrom
    (:func:`~openmm_symprk.analysis.structure.first_peak`), with block errors.  Needs a periodic box.

    Results, with InterRDF's names: ``bins`` (bin centres, Angstrom), ``edges`` (Angstrom), ``rdf`` (g); and
    ``rdf_se`` (its block standard error), ``rdf_blocks`` (each block's g), ``peak``
    (:class:`~openmm_symprk.analysis.structure.Peak`: ``r`` and ``r_se`` in Angstrom, ``height``, ``height_se``;
    or None with the reason in ``note``); ``units`` names each result's unit.
    """

    def __init__(self, atomgroup, *, nbins: int | None = None, range=None, n_blocks: int = 5,
                 peak_from: float = 2.0, masses=None, **kwargs):
        super().__init__(atomgroup, masses=masses, **kwargs)
        if nbins is not None and (int(nbins) != nbins or nbins < 1):
            raise InputError(f"nbins must be a positive integer, got {nbins!r}")
        if range is not None:
            lo, hi = (float(a) for a in range)
            if lo != 0.0 or not hi > 0:
                raise InputError(f"range must be (0, r_max) in Angstrom with r_max > 0 (g(r) is binned from 0), got "
                                 f"{(lo, hi)}")
        self._nbins, self._range, self._n_blocks, self._peak_from = nbins, range, n_blocks, peak_from

    def _analyse(self, x, v, box):
        if box is None:
            raise InputError("RadialDistribution needs a periodic box: the trajectory has none")
        oxygen = x[:, self.waters.molecules[:, 0]]
        r_max = 0.5 * float(box.min()) / ANGSTROM_IN_NM if self._range is None else float(self._range[1])
        nbins = self._nbins if self._nbins is not None else max(1, int(np.floor(r_max / BIN_WIDTH + 1e-9)))
        if self._nbins is None and self._range is None:
            r_max = nbins * BIN_WIDTH  # whole bins up to half the edge
        dr = r_max / nbins * ANGSTROM_IN_NM
        rdf = structure.radial_distribution(oxygen, box, nbins * dr, dr, min(self._n_blocks, len(x)))
        r = self.results
        r.edges = np.linspace(0.0, r_max, nbins + 1)
        r.bins = 0.5 * (r.edges[1:] + r.edges[:-1])
        r.rdf, r.rdf_se, r.rdf_blocks, r.peak, r.note = rdf.g, rdf.se, rdf.blocks, None, ""
        r.units = {"bins": "Angstrom", "edges": "Angstrom", "rdf": "", "rdf_se": "", "peak.r": "Angstrom",
                   "peak.height": ""}
        in_angstrom = structure.Rdf(r.bins, rdf.g, rdf.se, rdf.blocks, r_max / nbins)
        try:
            r.peak = structure.first_peak(in_angstrom, self._peak_from, unit="Angstrom")
        except ValueError as exc:
            r.note = str(exc)
