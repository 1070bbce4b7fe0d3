"""What every trajectory analysis of water shares: finding the waters of a Universe, reading their frames (in
MDAnalysis' units, Angstrom and ps, converted to the kernels' nm once), and the time between frames.  The
analyses take and give Angstrom and ps, as MDAnalysis does.

Waters (:func:`find_waters`): the residues of the atom group with exactly one oxygen and two hydrogens among
their atoms of non-zero mass (the element, else the name's first letter: OW, OH2, O; HW1, H1, H), any
massless sites (TIP4P's M, TIP5P's lone pairs) kept after them.  Each molecule's atoms are ordered O, H, H,
massless sites; every water must have the same number of sites (one model).  Masses are the topology's (an
OpenMM System's through ``masses=``), charges the topology's where it has them.

Frames (:class:`WaterFrames`): each frame's water positions (and velocities where asked) are copied as
float32 (what the file stores), with the box; every computation runs once over all frames at the end, in
float64 (the centres of mass a chunk of frames at a time), vectorised over frames and molecules (no Python
loop per molecule).  Memory: 12 bytes per site and
frame for positions, as much again for velocities (1000 frames of 216 waters: 7.8 MB).  Boxes must be
orthorhombic; without a box, positions are taken as continuous and molecules as whole, and are checked to be
(:mod:`.checks`: no molecule split; for diffusion, no centre of mass jumping across a box the file does not
store).  The molecules of the first frame are checked to be water (O-H and H-H distances), which a topology
listing the atoms in another order than the trajectory's is not.
"""
from __future__ import annotations

import inspect

import numpy as np

from ...conservation.analysis import group_masses
from ...support import InputError, require
from .checks import describe_steps, geometry_problem, time_steps, wrapped_problem

AnalysisBase = require("MDAnalysis.analysis.base", "analysis", "openmm_symprk.analysis.universe").AnalysisBase

__all__ = ["Waters", "find_waters", "WaterFrames", "ANGSTROM_IN_NM", "refuse_unknown_keywords"]

#: 1 Angstrom (MDAnalysis' length unit) in nm.
ANGSTROM_IN_NM = 0.1
_MASSLESS = 0.5  # amu: sites lighter than this are virtual sites
#: How to give a box to a trajectory that stores none (MDAnalysis' own transformation).
GIVE_A_BOX = ("give the box: u.trajectory.add_transformations(MDAnalysis.transformations.boxdimensions."
              "set_dimensions([a, b, c, 90, 90, 90])), or analyse unwrapped positions")


class Waters:
    """The waters of an atom group: ``atoms`` (the AtomGroup of every water site, molecule by molecule),
    ``molecules`` (n, k) indices into ``atoms`` ordered O, H, H, massless sites; ``masses`` (N,) amu and
    ``charges`` (N,) e or None, both of ``atoms``."""

    def __init__(self, atoms, molecules, masses, charges):
        self.atoms, self.molecules, self.masses, self.charges = atoms, molecules, masses, charges

    @property
    def n_molecules(self) -> int:
        return len(self.molecules)


def _symbol(atom) -> str:
    element = getattr(atom, "element", "") if hasattr(atom, "element") else ""
    if element:
        return str(element).strip().upper()
    name = str(atom.name).lstrip("0123456789")
    return name[:1].upper()


def find_waters(atomgroup, masses=None) -> Waters:
    """The waters (:class:`Waters`) among ``atomgroup``'s residues (see the module docstring); ValueError naming
    what was found when there are none or they are not all of one model.  ``masses``: None (the topology's), an
    array (one per atom of the group or of the Universe) or an ``openmm.System``."""
    if not hasattr(atomgroup, "residues"):
        raise TypeError(f"expected an MDAnalysis AtomGroup or Universe, got {type(atomgroup).__name__}")
    atomgroup = getattr(atomgroup, "atoms", atomgroup)
    try:
        all_masses = group_masses(atomgroup.universe.atoms, masses)
    except Exception as exc:  # noqa: BLE001 - a topology without masses: say so below
        if masses is not None:
            raise
        raise InputError(f"the topology has no masses ({exc}); pass masses=") from exc
    in_group = np.zeros(atomgroup.universe.atoms.n_atoms, dtype=bool)
    in_group[atomgroup.indices] = True
    mols, sizes = [], set()
    for res in atomgroup.residues:
        idx = [i for i in res.atoms.indices if in_group[i]]
        massive = [i for i in idx if all_masses[i] > _MASSLESS]
        symbols = [_symbol(atomgroup.universe.atoms[i]) for i in massive]
        if len(massive) != 3 or sorted(symbols) != ["H", "H", "O"]:
            continue
        o = massive[symbols.index("O")]
        hs = [i for i in massive if i != o]
        mols.append([o] + hs + [i for i in idx if i not in massive])
        sizes.add(len(idx))
    if not mols:
        names = sorted(set(atomgroup.residues.resnames))[:8]
        raise InputError(f"no water in the selection ({atomgroup.n_atoms} atoms, residues {', '.join(names)}): "
                         f"these analyses need water residues of one O and two H atoms (plus massless sites)")
    if len(sizes) != 1:
        raise InputError(f"the waters have different numbers of sites {sorted(sizes)}: analyse one water model "
                         f"at a time (select its residues)")
    flat = np.asarray(mols, dtype=int)
    atoms = atomgroup.universe.atoms[flat.ravel()]
    molecules = np.arange(flat.size).reshape(flat.shape)
    charges = None
    if hasattr(atomgroup.universe.atoms, "charges"):
        q = np.asarray(atoms.charges, dtype=np.float64)
        charges = q if np.any(q != 0) else None
    return Waters(atoms, molecules, all_masses[flat.ravel()], charges)


#: The keywords of AnalysisBase.run() that choose the frames.
RUN_KEYWORDS = ("start", "stop", "step", "frames")


def refuse_unknown_keywords(analysis, kwargs: dict) -> None:
    """TypeError naming ``kwargs`` (what the constructor of ``analysis`` received beyond its own parameters) and
    what it takes.  MDAnalysis' AnalysisBase accepts any keyword and ignores it, so ``stop=10`` given to a
    constructor would analyse every frame without a word; the frame range goes to ``.run()``."""
    if not kwargs:
        return
    name = type(analysis).__name__
    takes = [p for p in inspect.signature(type(analysis).__init__).parameters
             if p not in ("self", "atomgroup", "kwargs", "verbose")] + ["verbose"]
    where = (" (the frames to analyse, start/stop/step/frames, are chosen in .run(), as in MDAnalysis: "
             f"{name}(...).run(stop=100))" if set(kwargs) & set(RUN_KEYWORDS) else "")
    raise TypeError(f"{name}() got unexpected keyword argument{'s' if len(kwargs) > 1 else ''} "
                    f"{', '.join(repr(k) for k in kwargs)}{where}; it takes {', '.join(repr(t) for t in takes)}")


class WaterFrames(AnalysisBase):
    """Base of the water analyses: collects the waters' positions (and, with ``velocities=True``, velocities)
    at every analysed frame, then :meth:`_analyse` works on them in nm, ps.  ``atomgroup``: a Universe or an
    AtomGroup holding the waters; ``masses``: see :func:`find_waters`; ``verbose``: MDAnalysis' progress bar.
    Keywords a class does not take are refused (:func:`refuse_unknown_keywords`): the frames to analyse go to
    ``.run(start, stop, step, frames)``."""

    _needs_velocities = False
    #: Whether the analysis needs continuous centres of mass (diffusion): without a box, jumps are refused.
    _needs_continuous = False

    def __init__(self, atomgroup, masses=None, verbose: bool = False, **kwargs):
        refuse_unknown_keywords(self, kwargs)
        universe = getattr(atomgroup, "universe", atomgroup)
        super().__init__(universe.trajectory, verbose=verbose)
        self.waters = find_waters(atomgroup, masses)

    def _prepare(self):
        n = self.waters.atoms.n_atoms
        self._x = np.empty((self.n_frames, n, 3), dtype=np.float32)
        self._v = np.empty((self.n_frames, n, 3), dtype=np.float32) if self._needs_velocities else None
        self._box = np.full((self.n_frames, 3), np.nan)

    def _single_frame(self):
        i, ts = self._frame_index, self._ts
        self._x[i] = self.waters.atoms.positions
        if self._v is not None:
            if not ts.has_velocities:
                raise InputError(f"{type(self).__name__} needs velocities and frame {ts.frame} of the trajectory "
                                 f"has none (DCD, XTC and PDB store positions only: use a TRR, NetCDF or H5MD "
                                 f"trajectory written with velocities)")
            self._v[i] = self.waters.atoms.velocities
        dims = ts.dimensions
        if dims is not None and np.all(np.asarray(dims[:3]) > 0):
            if np.any(np.abs(np.asarray(dims[3:]) - 90.0) > 1e-3):
                raise InputError(f"frame {ts.frame} has a triclinic box (angles {np.round(dims[3:], 3).tolist()}): "
                                 f"these analyses need an orthorhombic box")
            self._box[i] = dims[:3]

    def check_frames(self, x, box) -> None:
        """ValueError when the frames ``x`` (F, N, 3) Angstrom (``box``: (F, 3) Angstrom or None) would give wrong
        figures silently: molecules that are not water in the first frame (the topology's atom order is not the
        trajectory's), or, without a box, molecules split across a box the file does not store (and, for
        :attr:`_needs_continuous` analyses, centres of mass jumping across it)."""
        w = self.waters
        residues = [f"residue {r.resname} {r.resid}" for r in w.atoms[w.molecules[:, 0]].residues]
        problem = None
        if box is None:  # first: a split molecule is not water either, but the reason is the missing box
            problem = wrapped_problem(x, w.masses, w.molecules, np.asarray(self.times), self.frames,
                                      jumps=self._needs_continuous)
            if problem is not None:
                problem += f"; {GIVE_A_BOX}"
        if problem is None:
            problem = geometry_problem(x[0], w.molecules, None if box is None else box[0], residues)
        if problem is not None:
            raise InputError(f"{type(self).__name__}: {problem}")

    def _conclude(self):
        x, v = self._x, self._v
        box = None if np.isnan(self._box).any() else self._box
        self.check_frames(x, box)
        x *= ANGSTROM_IN_NM  # in place, float32 (what the file stored): the kernels compute in float64
        if v is not None:
            v *= ANGSTROM_IN_NM
        box = None if box is None else box * ANGSTROM_IN_NM
        self._x = self._v = None
        self._analyse(x, v, box)

    def frame_interval_ps(self) -> float:
        """The time between analysed frames (ps); ValueError unless they are evenly spaced."""
        t = np.asarray(self.times, dtype=np.float64)
        if len(t) < 2:
            raise InputError(f"{type(self).__name__} needs at least 2 frames, got {len(t)}")
        dt, irregular = time_steps(t)
        if len(irregular):
            raise InputError(f"{describe_steps(t, irregular, self.frames)}: a time correlation needs a constant "
                             f"interval (analyse an evenly spaced piece: .run(start=, stop=))")
        return dt

    def _analyse(self, x, v, box):  # pragma: no cover - every analysis defines it
        raise NotImplementedError
