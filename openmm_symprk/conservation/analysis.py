"""MDAnalysis analysis of momentum conservation on stored trajectories (with velocities).

(The kinetic temperatures of molecules on a trajectory are :class:`openmm_symprk.analysis.universe.KineticTemperatures`.)

    import MDAnalysis as mda
    from openmm_symprk.conservation.analysis import AngularMomentum, LinearMomentum, universe
    u = universe(topology, "traj.trr", system=system)      # or mda.Universe("top.pdb", "traj.trr")
    L = AngularMomentum(u.atoms).run()
    L.results.total          # (n_frames, 3), amu nm^2/ps, about the centre of mass of the group
    L.results.relative_drift # |L(t) - L(0)| / |L(0)| per frame
    AngularMomentum(u.atoms, by="residues").run().results.groups   # (n_frames, n_residues, 3)

Both classes follow MDAnalysis' ``AnalysisBase`` pattern (``run(start, stop, step)``, results in
``.results``, ``.times``, ``.frames``).  They report in the units of :mod:`openmm_symprk.conservation`
(nm, ps, amu: MDAnalysis' Angstrom values are divided by 10) and compute in float64.

Masses.  ``mda.Universe("top.pdb", ...)`` guesses masses from elements, which differ from the
force field's by up to 0.003 amu; then P and L are not the conserved quantities of the simulated
system and drift at ~1e-5.  Pass ``masses=`` (an array, or the ``openmm.System``), or build the
Universe with :func:`universe`, which takes the masses and bonds (for ``by="fragments"``) from OpenMM.

The float32 floor.  TRR, XTC and DCD store positions and velocities in float32 (relative rounding
6e-8).  Figures recomputed from a stored frame therefore differ from the in-process float64 figures
(:mod:`.diagnostics`, :class:`~.reporters.ConservationReporter`) by
~1e-7 relative, independently at each frame: a stored trajectory cannot show conservation better than
|dL|/|L| ~ 1e-7, even when the simulation conserved L to 1e-14.  Use the in-process reporter for
figures below that floor; use stored trajectories for anything above it (thermostat, CMMotionRemover,
non-symplectic methods, per-residue exchange of angular momentum).
"""
from __future__ import annotations

import numpy as np
import openmm as mm
import openmm.unit as unit

from ..physics import momenta
from ..support import InputError, require
from ..systems.properties import masses as system_masses

AnalysisBase = require("MDAnalysis.analysis.base", "analysis", "openmm_symprk.conservation.analysis").AnalysisBase

__all__ = ["LinearMomentum", "AngularMomentum", "universe", "group_masses", "subgroups", "FLOAT32_FLOOR"]

#: Relative resolution of momentum figures recomputed from a float32 trajectory (documented above).
FLOAT32_FLOOR = 1e-7

_A = 0.1  # Angstrom -> nm


def group_masses(atomgroup, masses=None) -> np.ndarray:
    """Masses (amu) of the atoms of ``atomgroup``: its own (None), the ``openmm.System``'s, or an array (one per
    atom of the group or of the whole Universe)."""
    if masses is None:
        return np.asarray(atomgroup.masses, dtype=np.float64)
    if isinstance(masses, mm.System):
        allm = system_masses(masses)
        return allm[atomgroup.indices]
    m = np.asarray(masses, dtype=np.float64)
    if m.shape != (atomgroup.n_atoms,):
        if m.shape == (atomgroup.universe.atoms.n_atoms,):
            return m[atomgroup.indices]
        raise InputError(f"masses has shape {m.shape}, expected ({atomgroup.n_atoms},)")
    return m


def subgroups(atomgroup, by):
    """Index arrays (into ``atomgroup``) of its ``by`` = "residues", "fragments" or "segments", or None for None."""
    if by is None:
        return None
    if by not in ("residues", "fragments", "segments"):
        raise InputError(f"by must be None, 'residues', 'fragments' or 'segments', got {by!r}")
    if by == "fragments" and not hasattr(atomgroup, "fragments"):
        raise InputError("by='fragments' needs bonds: build the Universe with openmm_symprk.conservation.analysis.universe() "
                         "or mda.Universe(..., guess_bonds=True)")
    pos = {ix: k for k, ix in enumerate(atomgroup.indices)}
    out = []
    for g in getattr(atomgroup, by):
        sel = [pos[i] for i in g.atoms.indices if i in pos]
        if sel:
            out.append(np.asarray(sel, dtype=int))
    return out


class _MomentumBase(AnalysisBase):
    def __init__(self, atomgroup, masses=None, by=None, **kwargs):
        super().__init__(atomgroup.universe.trajectory, **kwargs)
        self._ag = atomgroup
        self._m = group_masses(atomgroup, masses)
        self._by = by
        self._sub = subgroups(atomgroup, by)

    def _state(self):
        ts = self._ts
        if not ts.has_velocities:
            raise InputError("the trajectory has no velocities (write it with VelocityTRRReporter, or any TRR/H5MD "
                             "with velocities); DCD and XTC store positions only")
        x = self._ag.positions.astype(np.float64) * _A
        v = self._ag.velocities.astype(np.float64) * _A
        return x, v

    def _prepare(self):
        self.results.total = np.zeros((self.n_frames, 3))
        if self._sub is not None:
            self.results.groups = np.zeros((self.n_frames, len(self._sub), 3))

    def _conclude(self):
        tot = self.results.total
        ref = tot[0] if len(tot) else np.zeros(3)
        scale = self._scale()
        self.results.drift = np.linalg.norm(tot - ref, axis=1)
        self.results.relative_drift = self.results.drift / scale if scale > 0 else np.full(len(tot), np.nan)


class LinearMomentum(_MomentumBase):
    """Total linear momentum sum m v (amu nm/ps) per frame, float64.

    ``by``: None, "residues", "fragments" or "segments" adds ``results.groups`` (n_frames, n_groups, 3).
    ``results.relative_drift`` divides |P - P0| by sum m|v| of the first frame (P0 is often ~0)."""

    def _single_frame(self):
        x, v = self._state()
        self.results.total[self._frame_index] = momenta.linear_momentum(v, self._m)
        if self._sub is not None:
            for k, g in enumerate(self._sub):
                self.results.groups[self._frame_index, k] = momenta.linear_momentum(v[g], self._m[g])
        if self._frame_index == 0:
            self._p_scale = float((self._m[:, None] * np.abs(v)).sum())

    def _scale(self):
        return getattr(self, "_p_scale", 0.0)


class AngularMomentum(_MomentumBase):
    """Total angular momentum sum m (x - c) x v (amu nm^2/ps) per frame, float64.

    ``about``: "com" (the group's centre of mass at that frame, default) or "origin".  With ``by``,
    ``results.groups`` holds each sub-group's angular momentum about its own centre of mass
    (not conserved individually: groups exchange angular momentum through their interactions)."""

    def __init__(self, atomgroup, about: str = "com", masses=None, by=None, **kwargs):
        if about not in ("com", "origin"):
            raise InputError(f"about must be 'com' or 'origin', got {about!r}")
        super().__init__(atomgroup, masses=masses, by=by, **kwargs)
        self._about = about

    @staticmethod
    def _L(x, v, m, about):
        if m.sum() <= 0:
            return np.zeros(3)
        return momenta.angular_momentum(x, v, m, about=about)

    def _single_frame(self):
        x, v = self._state()
        self.results.total[self._frame_index] = self._L(x, v, self._m, self._about)
        if self._sub is not None:
            for k, g in enumerate(self._sub):
                self.results.groups[self._frame_index, k] = self._L(x[g], v[g], self._m[g], "com")

    def _scale(self):
        return float(np.linalg.norm(self.results.total[0])) if len(self.results.total) else 0.0


def universe(topology, trajectory=None, system: mm.System | None = None, positions=None):
    """An MDAnalysis Universe from an OpenMM Topology (names, residues, chains as segments, elements,
    bonds) with the System's masses, optionally loading ``trajectory`` (e.g. a TRR written by
    :class:`~.reporters.VelocityTRRReporter`).  Without a trajectory, ``positions``
    (nm) give a single frame."""
    mda = require("MDAnalysis", "analysis", "openmm_symprk.conservation.analysis.universe")

    atoms = list(topology.atoms())
    residues = list(topology.residues())
    chains = list(topology.chains())
    res_index = {r: k for k, r in enumerate(residues)}
    chain_index = {c: k for k, c in enumerate(chains)}
    u = mda.Universe.empty(len(atoms), n_residues=max(len(residues), 1), n_segments=max(len(chains), 1),
                           atom_resindex=[res_index[a.residue] for a in atoms],
                           residue_segindex=[chain_index[r.chain] for r in residues] or [0],
                           trajectory=trajectory is None and positions is not None)
    u.add_TopologyAttr("names", [a.name for a in atoms])
    u.add_TopologyAttr("elements", [a.element.symbol if a.element is not None else "" for a in atoms])
    u.add_TopologyAttr("resnames", [r.name for r in residues])
    u.add_TopologyAttr("resids", [int(r.id) if str(r.id).lstrip("-").isdigit() else k + 1
                                  for k, r in enumerate(residues)])
    u.add_TopologyAttr("segids", [str(c.id) for c in chains] or ["A"])
    if system is not None:
        u.add_TopologyAttr("masses", system_masses(system))
    else:
        u.add_TopologyAttr("masses", [a.element.mass.value_in_unit(unit.dalton) if a.element is not None else 0.0
                                      for a in atoms])
    u.add_TopologyAttr("bonds", [(b[0].index, b[1].index) for b in topology.bonds()])
    if trajectory is not None:
        u.load_new(trajectory)
    elif positions is not None:
        x = positions.value_in_unit(unit.nanometer) if unit.is_quantity(positions) else positions
        u.atoms.positions = np.asarray(x, dtype=np.float64) * 10.0
    return u
