"""Molecules along a trajectory: centre-of-mass frames of every molecule at every frame (pure numpy).

One definition of a molecule's centre-of-mass frame is :func:`openmm_symprk.physics.momenta.molecule_frames`;
this module only stacks the frames of a trajectory into one call.  Units: nm, ps, Da.
"""
from __future__ import annotations

import numpy as np

from ...physics.momenta import MoleculeFrames, molecule_frames

__all__ = ["trajectory_frames", "centre_of_mass_trajectory", "molecule_index"]


def molecule_index(molecules) -> np.ndarray:
    """An (n, k) index array from ``molecules`` (lists of atom indices, all of the same length k)."""
    try:
        idx = np.asarray(molecules, dtype=int)
    except ValueError:
        idx = None
    if idx is None or idx.ndim != 2 or idx.shape[0] == 0 or idx.shape[1] == 0:
        sizes = sorted({len(g) for g in molecules}) if hasattr(molecules, "__iter__") else None
        raise ValueError(f"molecules must be a non-empty list of atom-index lists all of one length (one kind of "
                         f"molecule, e.g. water); got lengths {sizes}")
    return idx


def _trajectory(x, name):
    x = np.asarray(x, dtype=np.float64)
    if x.ndim != 3 or x.shape[2] != 3:
        raise ValueError(f"{name} must have shape (n_frames, n_atoms, 3) in nm or nm/ps, got {x.shape}")
    return x


def trajectory_frames(x, v, m, molecules) -> MoleculeFrames:
    """The centre-of-mass frames (:class:`~openmm_symprk.physics.momenta.MoleculeFrames`) of every molecule
    at every frame, each field with a leading frame axis: M (F, n), com and V (F, n, 3), r (F, n, k, 3),
    L (F, n, 3) in Da nm^2/ps, inertia (F, n, 3, 3) in Da nm^2.  ``x`` (F, N, 3) nm, ``v`` (F, N, 3) nm/ps or
    None (zero velocities: positions-only quantities), ``m`` (N,) Da; molecules must be whole in ``x``."""
    x = _trajectory(x, "x")
    v = np.zeros_like(x) if v is None else _trajectory(v, "v")
    if v.shape != x.shape:
        raise ValueError(f"v has shape {v.shape}, x has {x.shape}: they must match")
    idx = molecule_index(molecules)
    f, n_atoms = x.shape[:2]
    m = np.asarray(m, dtype=np.float64)
    if m.shape != (n_atoms,):
        raise ValueError(f"m must have shape ({n_atoms},) (one mass per atom, Da), got {m.shape}")
    stacked = (idx[None] + n_atoms * np.arange(f)[:, None, None]).reshape(-1, idx.shape[1])
    fr = molecule_frames(x.reshape(-1, 3), v.reshape(-1, 3), np.tile(m, f), stacked)
    n = idx.shape[0]
    return MoleculeFrames(*(a.reshape((f, n) + a.shape[1:]) for a in fr))


def centre_of_mass_trajectory(x, m, molecules) -> np.ndarray:
    """Centres of mass (F, n, 3) nm of the molecules along the trajectory ``x`` (F, N, 3) nm."""
    return trajectory_frames(x, None, m, molecules).com
