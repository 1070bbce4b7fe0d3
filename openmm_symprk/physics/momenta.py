"""Momenta of a set of point masses, in float64 (nm, ps, Da; momentum Da nm/ps, angular momentum Da nm^2/ps).

Every function takes positions ``x`` (N, 3), velocities ``v`` (N, 3) and masses ``m`` (N,) as arrays.
Points about which a moment is taken are stated by the caller: ``about="com"`` (the centre of mass of the
same particles), ``"origin"``, or a point (3,).  In an isolated system L about the centre of mass and L
about the origin are both conserved (L_origin = L_com + M r_cm x V_cm with V_cm constant); a
CMMotionRemover keeps the first and changes the second, so the two must never be confused.
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ..support.errors import InputError

__all__ = ["centre_of_mass", "linear_momentum", "angular_momentum", "inertia_tensor", "kinetic_energy",
           "reference_point", "MoleculeFrames", "molecule_frames"]


def _arrays(*arrays):
    return [np.asarray(a, dtype=np.float64) for a in arrays]


def centre_of_mass(x, m) -> np.ndarray:
    """sum m x / sum m, shape (3,); ValueError if every particle is massless."""
    x, m = _arrays(x, m)
    total = m.sum()
    if not total > 0:
        raise InputError("the particles have no mass (all massless): no centre of mass")
    return (m[:, None] * x).sum(axis=0) / total


def reference_point(x, m, about) -> np.ndarray:
    """The point a moment is taken about: "com", "origin" or an explicit point (nm)."""
    if isinstance(about, str):
        if about == "com":
            return centre_of_mass(x, m)
        if about == "origin":
            return np.zeros(3)
        raise InputError(f"about must be 'com', 'origin' or a point (nm), got {about!r}")
    point = np.asarray(about, dtype=np.float64)
    if point.shape != (3,):
        raise InputError(f"about must be 'com', 'origin' or a point of 3 coordinates (nm), got {about!r}")
    return point


def linear_momentum(v, m) -> np.ndarray:
    """sum m v, shape (3,)."""
    v, m = _arrays(v, m)
    return (m[:, None] * v).sum(axis=0)


def angular_momentum(x, v, m, *, about) -> np.ndarray:
    """sum m (x - c) x v about c = ``about`` ("com", "origin" or a point), shape (3,)."""
    x, v, m = _arrays(x, v, m)
    c = reference_point(x, m, about)
    return (m[:, None] * np.cross(x - c, v)).sum(axis=0)


def inertia_tensor(x, m, *, about) -> np.ndarray:
    """sum m (|r|^2 I - r r^T) with r = x - c, c = ``about``; shape (3, 3)."""
    x, m = _arrays(x, m)
    r = x - reference_point(x, m, about)
    return np.eye(3) * (m * (r * r).sum(axis=1)).sum() - np.einsum("i,ij,ik->jk", m, r, r)


def kinetic_energy(v, m) -> float:
    """1/2 sum m |v|^2 (kJ/mol for Da nm^2/ps^2)."""
    v, m = _arrays(v, m)
    return float(0.5 * (m[:, None] * v * v).sum())


class MoleculeFrames(NamedTuple):
    """Per molecule (batched): mass M (n,), centre of mass (n, 3) and its velocity V (n, 3), atom positions
    relative to it r (n, k, 3), angular momentum about it L (n, 3) and inertia tensor about it (n, 3, 3)."""

    M: np.ndarray
    com: np.ndarray
    V: np.ndarray
    r: np.ndarray
    L: np.ndarray
    inertia: np.ndarray


def molecule_frames(x, v, m, idx) -> MoleculeFrames:
    """Centre-of-mass frames of n molecules of k atoms each (``idx``: an (n, k) index array), each moment
    about the molecule's own centre of mass.  A massless molecule gets M = 0, its centre of mass and V at
    the origin (so it carries nothing)."""
    x, v, m = _arrays(x, v, m)
    idx = np.asarray(idx, dtype=int)
    mg, xg, vg = m[idx], x[idx], v[idx]
    M = mg.sum(axis=1)
    Mw = np.where(M > 0, M, 1.0)[:, None]
    com = (mg[..., None] * xg).sum(axis=1) / Mw
    V = (mg[..., None] * vg).sum(axis=1) / Mw
    r = xg - com[:, None, :]
    L = (mg[..., None] * np.cross(r, vg - V[:, None, :])).sum(axis=1)
    inertia = np.eye(3) * (mg * (r * r).sum(axis=2)).sum(axis=1)[:, None, None] - np.einsum("ni,nij,nik->njk", mg, r, r)
    return MoleculeFrames(M, com, V, r, L, inertia)
