"""The motion of a rigid group of point masses, on arrays (nm, Da, ps; no OpenMM): its principal axes, the
velocities of a rigid motion, the rotation of its body frame (mass-weighted Kabsch) and its body-frame angular
momentum, about the centre of mass (:mod:`.momenta` sums the moments)."""
from __future__ import annotations

import numpy as np

from . import momenta

__all__ = ["principal_axes", "rigid_body_velocities", "body_frame_rotation", "body_angular_momentum"]


def principal_axes(positions, masses):
    """(centre of mass, principal moments ascending, axes) with axes a proper rotation (columns)."""
    r = np.asarray(positions, float)
    m = np.asarray(masses, float)
    com = momenta.centre_of_mass(r, m)
    moments, axes = np.linalg.eigh(momenta.inertia_tensor(r, m, about="com"))
    if np.linalg.det(axes) < 0:
        axes[:, 2] *= -1
    return com, moments, axes


def rigid_body_velocities(positions, masses, angular_velocity, com_velocity=(0.0, 0.0, 0.0)) -> np.ndarray:
    """Velocities v_i = V + ω × (r_i - c) of a rigid motion (space-frame ω, nm/ps and 1/ps)."""
    r = np.asarray(positions, float)
    m = np.asarray(masses, float)
    com = momenta.centre_of_mass(r, m)
    return np.asarray(com_velocity, float) + np.cross(np.asarray(angular_velocity, float), r - com)


def body_frame_rotation(body_coords, positions, masses) -> np.ndarray:
    """The proper rotation R that best maps the body coordinates onto ``positions`` - com (mass-weighted
    Kabsch), so that positions ≈ com + body_coords @ Rᵀ."""
    m = np.asarray(masses, float)
    r = np.asarray(positions, float)
    r = r - momenta.centre_of_mass(r, m)
    b = np.asarray(body_coords, float)
    H = (m[:, None] * b).T @ r
    U, _, Vt = np.linalg.svd(H)
    d = np.sign(np.linalg.det(Vt.T @ U.T))
    return Vt.T @ np.diag([1.0, 1.0, d]) @ U.T


def body_angular_momentum(body_coords, positions, velocities, masses):
    """(x, L, R): body-frame angular momentum x = RᵀL, space-frame L and the body rotation R."""
    L = momenta.angular_momentum(positions, velocities, masses, about="com")
    R = body_frame_rotation(body_coords, positions, masses)
    return R.T @ L, L, R
