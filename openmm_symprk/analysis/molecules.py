"""Molecules along a trajectory (pure numpy): their atoms made whole across periodic boundaries, their centres
of mass, and the centre-of-mass frames of every molecule at every frame.  Units: nm, ps, Da.

One definition of a molecule's centre-of-mass frame is :func:`openmm_symprk.physics.momenta.molecule_frames`;
this module stacks the frames of a trajectory into one call.  :func:`make_whole` puts each molecule's atoms
at the minimum image of its first atom (a molecule smaller than half the box: any water), as a trajectory
written with atoms wrapped into the box (most engines' default) needs before anything about a molecule is
computed; positions from OpenMM without ``enforcePeriodicBox`` are whole already, and it leaves them as they are.
"""
from __future__ import annotations

import numpy as np

from ..physics.momenta import MoleculeFrames, molecule_frames
from ..support.errors import InputError

__all__ = ["trajectory_frames", "centre_of_mass_trajectory", "molecule_index", "make_whole", "check_box"]


def molecule_index(molecules) -> np.ndarray:
    """An (n, k) index array from ``molecules`` (lists of atom indices, all of the same length k)."""
    try:
        idx = np.asarray(molecules, dtype=int)
    except ValueError:
        idx = None
    if idx is None or idx.ndim != 2 or idx.shape[0] == 0 or idx.shape[1] == 0:
        sizes = sorted({len(g) for g in molecules}) if hasattr(molecules, "__iter__") else None
        raise InputError(f"molecules must be a non-empty list of atom-index lists all of one length (one kind of "
                         f"molecule, e.g. water); got lengths {sizes}")
    return idx


def check_box(box, n_frames: int | None = None) -> np.ndarray:
    """The box as float64 edge lengths (nm): (3,), or (F, 3) one per frame when ``n_frames`` is given (a (3,)
    box is then repeated); ValueError unless every edge is > 0 (orthorhombic boxes only)."""
    b = np.asarray(box, dtype=np.float64)
    if n_frames is not None and b.shape == (3,):
        b = np.broadcast_to(b, (n_frames, 3))
    want = (3,) if n_frames is None else (n_frames, 3)
    if b.shape != want or not np.all(b > 0):
        raise InputError(f"box must be the 3 edge lengths (nm, all > 0) of an orthorhombic box"
                         f"{'' if n_frames is None else ', or one row of 3 per frame'}, got shape {b.shape}")
    return b


def make_whole(x, molecules, box) -> np.ndarray:
    """Positions (F, n, k, 3) nm of the k atoms of each of the n ``molecules`` in ``x`` (F, N, 3) nm, each atom
    moved to the periodic image nearest the molecule's first atom in the orthorhombic ``box`` (3 edges nm, or
    (F, 3) one per frame; None: ``x`` is whole already)."""
    x = np.asarray(x)
    if x.ndim != 3 or x.shape[2] != 3:
        raise InputError(f"x must have shape (n_frames, n_atoms, 3) in nm, got {x.shape}")
    xg = x[:, molecule_index(molecules)].astype(np.float64)
    if box is not None:
        b = check_box(box, x.shape[0])[:, None, None, :]
        d = xg - xg[:, :, :1]
        shift = np.divide(d, b)
        np.round(shift, out=shift)
        shift *= b
        xg -= shift
    return xg


def _trajectory(x, name):
    x = np.asarray(x, dtype=np.float64)
    if x.ndim != 3 or x.shape[2] != 3:
        raise InputError(f"{name} must have shape (n_frames, n_atoms, 3) in nm or nm/ps, got {x.shape}")
    return x


def trajectory_frames(x, v, m, molecules) -> MoleculeFrames:
    """The centre-of-mass frames (:class:`~openmm_symprk.physics.momenta.MoleculeFrames`) of every molecule
    at every frame, each field with a leading frame axis: M (F, n), com and V (F, n, 3), r (F, n, k, 3),
    L (F, n, 3) in Da nm^2/ps, inertia (F, n, 3, 3) in Da nm^2.  ``x`` (F, N, 3) nm, ``v`` (F, N, 3) nm/ps or
    None (zero velocities: positions-only quantities), ``m`` (N,) Da; molecules must be whole in ``x``."""
    x = _trajectory(x, "x")
    v = np.zeros_like(x) if v is None else _trajectory(v, "v")
    if v.shape != x.shape:
        raise InputError(f"v has shape {v.shape}, x has {x.shape}: they must match")
    idx = molecule_index(molecules)
    f, n_atoms = x.shape[:2]
    m = np.asarray(m, dtype=np.float64)
    if m.shape != (n_atoms,):
        raise InputError(f"m must have shape ({n_atoms},) (one mass per atom, Da), got {m.shape}")
    stacked = (idx[None] + n_atoms * np.arange(f)[:, None, None]).reshape(-1, idx.shape[1])
    fr = molecule_frames(x.reshape(-1, 3), v.reshape(-1, 3), np.tile(m, f), stacked)
    n = idx.shape[0]
    return MoleculeFrames(*(a.reshape((f, n) + a.shape[1:]) for a in fr))


def centre_of_mass_trajectory(x, m, molecules, box=None, chunk: int = 256) -> np.ndarray:
    """Centres of mass (F, n, 3) nm of the molecules along the trajectory ``x`` (F, N, 3) nm with masses ``m``
    (N,) Da (the :func:`~openmm_symprk.physics.momenta.molecule_frames` centre, without the rest of the
    frame); with ``box``, of the molecules made whole first (:func:`make_whole`).  Computed ``chunk`` frames at a
    time, so that float32 frames are never copied whole into float64."""
    x = np.asarray(x)
    if x.ndim != 3 or x.shape[2] != 3:
        raise InputError(f"x must have shape (n_frames, n_atoms, 3) in nm, got {x.shape}")
    m = np.asarray(m, dtype=np.float64)
    if m.shape != (x.shape[1],):
        raise InputError(f"m must have shape ({x.shape[1]},) (one mass per atom, Da), got {m.shape}")
    idx = molecule_index(molecules)
    mg = m[idx]
    total = mg.sum(axis=1)
    if np.any(total <= 0):
        raise InputError("a molecule has no mass: no centre of mass")
    w = mg / total[:, None]
    boxes = None if box is None else check_box(box, x.shape[0])
    out = np.empty((x.shape[0], len(idx), 3))
    for a in range(0, x.shape[0], chunk):
        b = min(a + chunk, x.shape[0])
        xg = make_whole(x[a:b], idx, None if boxes is None else boxes[a:b])
        out[a:b] = np.einsum("nk,fnkd->fnd", w, xg)
    return out
