"""Reorientation of the waters on any Universe (:class:`Reorientation`)."""
from __future__ import annotations

import numpy as np

from .. import reorientation
from .base import WaterFrames
from ...support.errors import InputError

__all__ = ["Reorientation", "VECTORS"]

#: The molecule-fixed vectors of water, by name.
VECTORS = ("dipole", "HH", "OH")


class Reorientation(WaterFrames):
    """Legendre correlation functions C_1, C_2 of water's dipole, H-H and O-H unit vectors over every time
    origin, and their correlation times tau_1, tau_2 (ps) with jackknife errors over ``n_groups`` groups of
    molecules (:func:`~openmm_symprk.analysis.reorientation.molecules_correlation_time`: the integral of C_l to where it
    falls to ``c_cut``, an exponential tail fitted between ``c_fit`` and ``c_cut``).

    The dipole is sum q_i x_i from the topology's charges (massless charge sites included), or the H-H
    bisector (the dipole's direction in 3-, 4- and 5-site waters) when the topology has no charges.  "OH"
    averages both O-H bonds.  ``vectors``, ``orders``: which to compute; ``max_lag``: the longest lag, frames
    (default half the analysed frames).

    Results: ``lag_ps``; ``C[vector]["C1"]`` ... the curves (molecule average); ``tau[vector]["tau1"]``
    (:class:`~openmm_symprk.analysis.reorientation.CorrelationTime`, ps, or None); ``notes[vector]["tau1"]``
    says why a time is missing (a curve that does not decay to ``c_cut`` within the lags); ``dipole_from``:
    "charges" or "bisector"; ``units``.
    """

    def __init__(self, atomgroup, vectors=VECTORS, orders=(1, 2), *, max_lag: int | None = None,
                 c_cut: float = 0.1, c_fit: float = 0.5, n_groups: int = 20, masses=None, **kwargs):
        super().__init__(atomgroup, masses=masses, **kwargs)
        bad = [v for v in vectors if v not in VECTORS] + [o for o in orders if o not in (1, 2)]
        if bad or not vectors or not orders:
            raise InputError(f"vectors must be among {VECTORS} and orders among (1, 2); got {list(vectors)}, "
                             f"{list(orders)}")
        self._vectors, self._orders = tuple(vectors), tuple(orders)
        self._options = dict(max_lag=max_lag, c_cut=c_cut, c_fit=c_fit, n_groups=n_groups)

    def unit_vectors(self, x, box, name: str) -> np.ndarray:
        """Unit vectors (F, n, 3) (or (F, 2n, 3) for "OH") of the vector ``name`` from water positions ``x``."""
        w = self.waters
        if name == "HH":
            return reorientation.atom_vectors(x, w.molecules, 1, 2, box)
        if name == "OH":
            return np.concatenate([reorientation.atom_vectors(x, w.molecules, 0, 1, box),
                                   reorientation.atom_vectors(x, w.molecules, 0, 2, box)], axis=1)
        if w.charges is not None:
            return reorientation.dipole_vectors(x, w.molecules, w.charges, box)
        return reorientation.bisector_vectors(x, w.molecules, box=box)

    def _analyse(self, x, v, box):
        dt = self.frame_interval_ps()
        o = self._options
        r = self.results
        r.C, r.tau, r.notes = {}, {}, {}
        r.dipole_from = "charges" if self.waters.charges is not None else "bisector"
        for name in self._vectors:
            u = self.unit_vectors(x, box, name)
            r.C[name], r.tau[name], r.notes[name] = {}, {}, {}
            for order in self._orders:
                c = reorientation.legendre_correlation(u, order, o["max_lag"])
                r.C[name][f"C{order}"] = c.mean(axis=1)
                try:
                    tau = reorientation.molecules_correlation_time(c, dt, n_groups=o["n_groups"], c_cut=o["c_cut"],
                                                                   c_fit=o["c_fit"])
                except ValueError as exc:
                    tau = None
                    r.notes[name][f"tau{order}"] = str(exc)
                r.tau[name][f"tau{order}"] = tau
        r.lag_ps = np.arange(len(next(iter(r.C.values()))[f"C{self._orders[0]}"])) * dt
        r.units = {"lag_ps": "ps", "C": "", "tau": "ps"}
