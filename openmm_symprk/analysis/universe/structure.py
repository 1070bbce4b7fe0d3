"""The O-O radial distribution function of the waters on any Universe (:class:`RadialDistribution`)."""
from __future__ import annotations

from .. import structure
from .base import WaterFrames

__all__ = ["RadialDistribution"]


class RadialDistribution(WaterFrames):
    """g(r) of the waters' oxygens (:func:`~openmm_symprk.analysis.structure.radial_distribution`: MDAnalysis'
    InterRDF in ``n_blocks`` blocks of frames) in bins of ``dr`` nm up to ``r_max`` nm (default half the
    shortest edge), and its first peak beyond ``r_min`` nm
    (:func:`~openmm_symprk.analysis.structure.first_peak`), with block errors.  Needs a periodic box.

    Results: ``rdf`` (:class:`~openmm_symprk.analysis.structure.Rdf`: r, g, se, blocks), ``r``, ``g``,
    ``peak`` (:class:`~openmm_symprk.analysis.structure.Peak`, or None with the reason in ``note``).
    """

    def __init__(self, atomgroup, r_max: float | None = None, dr: float = 0.005, *, n_blocks: int = 5,
                 r_min: float = 0.2, masses=None, **kwargs):
        super().__init__(atomgroup, masses=masses, **kwargs)
        self._r_max, self._dr, self._n_blocks, self._r_min = r_max, dr, n_blocks, r_min

    def _analyse(self, x, v, box):
        if box is None:
            raise ValueError("RadialDistribution needs a periodic box: the trajectory has none")
        oxygen = x[:, self.waters.molecules[:, 0]]
        r_max = 0.5 * float(box.min()) if self._r_max is None else self._r_max
        rdf = structure.radial_distribution(oxygen, box, r_max, self._dr, min(self._n_blocks, len(x)))
        r = self.results
        r.rdf, r.r, r.g, r.peak, r.note = rdf, rdf.r, rdf.g, None, ""
        try:
            r.peak = structure.first_peak(rdf, self._r_min)
        except ValueError as exc:
            r.note = str(exc)
