"""Canonical sampling through velocity rescaling (Bussi, Donadio and Parrinello, J. Chem. Phys. 126, 014101,
2007), as pure numerics: the rescaling factor, its noise, and the split of velocities into the part the
thermostat keeps and the part it rescales.  Units: nm, ps, Da, kJ/mol.

The thermostat acts on the kinetic energy K of the *peculiar* velocities (what is left after the motion that
must be kept: the centre-of-mass velocity always, and the rigid rotation about the centre of mass too for an
isolated system).  Over an interval t with c = exp(-t/tau) its kinetic energy follows the exact solution of

    dK = (K_target - K) dt/tau + 2 sqrt(K K_target / N_f) dW/sqrt(tau),     K_target = N_f kT / 2,

which is: treat the N_f peculiar velocity components as an Ornstein-Uhlenbeck vector that relaxes with rate
1/(2 tau) towards zero and is driven by noise of the canonical strength, and keep only its length.  Along
the current velocity the vector becomes sqrt(c K) + sqrt((1-c) K_target / N_f) R1, across it the noise
contributes (1-c) K_target / N_f times a chi-squared variable S of N_f - 1 degrees of freedom, so

    K' = c K + (1 - c) K_target (R1^2 + S) / N_f + 2 R1 sqrt(c (1 - c) K K_target / N_f),

with R1 a standard normal.  Every peculiar velocity is multiplied by alpha = +-sqrt(K'/K), with the sign of
the component along the velocity, sign(R1 + sqrt(c N_f K / ((1 - c) K_target))).  One factor for all
particles: the peculiar velocities keep zero total momentum (and zero angular momentum when the rotation
is kept), and velocity constraints, being linear, stay satisfied.  The energy the bath gives is K' - K;
the heat-bath energy is minus its running sum, so total energy plus heat-bath energy is conserved up to
the integrator's own error.
"""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from .momenta import angular_momentum, centre_of_mass, inertia_tensor, kinetic_energy, linear_momentum
from ..support.errors import InputError

__all__ = ["thermostat_dof", "relaxation_factor", "rescaling_factor", "draw_noise", "Resampled", "resample",
           "kept_velocities", "peculiar_kinetic_energy", "ROUNDOFF", "no_peculiar_motion"]

#: A peculiar kinetic energy at most this fraction of the total is round-off (a system at rest, or moving only as a
#: rigid whole): an event leaves it alone, since sqrt(K'/K_pec) ~ 1e8 would amplify round-off into the kept motion.
ROUNDOFF = 1e-10


def no_peculiar_motion(kinetic: float, total_kinetic: float) -> bool:
    """True where there is nothing to rescale: the peculiar kinetic energy ``kinetic`` is at most
    :data:`ROUNDOFF` of the total ``total_kinetic`` (both kJ/mol; 0 and 0 for a system at rest)."""
    return not kinetic > ROUNDOFF * total_kinetic


def thermostat_dof(n_massive: int, n_constraints: int, isolated: bool) -> int:
    """Degrees of freedom the thermostat samples: 3 per particle with mass (virtual sites and massless
    particles never move by themselves), minus one per constraint, minus 3 for the centre-of-mass velocity
    (always kept), minus the rigid rotations when the system is isolated (kept too): 3, but 2 for two particles
    with mass (a linear system has no rotation about its axis; the kept rotation is solved with a regularised
    inertia tensor, which leaves that axis alone) and 0 for one."""
    n = int(n_massive)
    rotations = (3 if n > 2 else (2 if n == 2 else 0)) if isolated else 0
    return 3 * n - int(n_constraints) - 3 - rotations


def relaxation_factor(interval: float, collision_time: float) -> float:
    """c = exp(-interval / collision_time) (both in ps); 0 for an infinitely strong coupling."""
    if not interval >= 0 or not collision_time > 0:
        raise InputError(f"need interval >= 0 and collision_time > 0 (ps), got {interval!r}, {collision_time!r}")
    return math.exp(-interval / collision_time)


def rescaling_factor(kinetic: float, target: float, dof: int, c: float, r1: float, chi2: float,
                     total_kinetic: float | None = None) -> tuple:
    """(alpha, K') for the peculiar kinetic energy ``kinetic`` (kJ/mol), the target N_f kT/2, the relaxation
    factor c = exp(-t/tau), a standard normal ``r1`` and a chi-squared variable ``chi2`` of dof - 1 degrees
    of freedom.  Deterministic: the native kernels compute the same expression from the same two numbers.
    ``total_kinetic``: the total kinetic energy, kept motion included; where the peculiar part is round-off of it
    (:func:`no_peculiar_motion`) the factor is 1, as where ``kinetic`` is not positive."""
    if not kinetic > 0 or (total_kinetic is not None and no_peculiar_motion(kinetic, total_kinetic)):
        # No peculiar motion to scale (all particles at the kept velocity): nothing can be rescaled.
        return 1.0, float(kinetic)
    s = target / dof
    new = c * kinetic + (1.0 - c) * s * (r1 * r1 + chi2) + 2.0 * r1 * math.sqrt(c * (1.0 - c) * kinetic * s)
    alpha = math.sqrt(max(new, 0.0) / kinetic)
    if c < 1.0 and r1 + math.sqrt(c * kinetic / ((1.0 - c) * s)) < 0:
        alpha = -alpha  # the velocity came out reversed along itself
    return alpha, new


def draw_noise(rng: np.random.Generator, dof: int) -> tuple:
    """(R1, S): a standard normal and a chi-squared variable of dof - 1 degrees of freedom (2 Gamma((dof-1)/2))."""
    if dof < 1:
        raise InputError(f"the thermostat needs at least one degree of freedom, got {dof}")
    r1 = float(rng.standard_normal())
    chi2 = 2.0 * float(rng.standard_gamma(0.5 * (dof - 1))) if dof > 1 else 0.0
    return r1, chi2


class Resampled(NamedTuple):
    alpha: float  # factor applied to the peculiar velocities
    kinetic: float  # their kinetic energy before (kJ/mol)
    new_kinetic: float  # and after


def resample(kinetic: float, target: float, dof: int, c: float, rng: np.random.Generator,
             total_kinetic: float | None = None) -> Resampled:
    """One thermostat event: draw the noise and return the factor and the kinetic energies before and after."""
    alpha, new = rescaling_factor(kinetic, target, dof, c, *draw_noise(rng, dof), total_kinetic=total_kinetic)
    return Resampled(alpha, float(kinetic), new)


def kept_velocities(x, v, m, keep_rotation: bool) -> np.ndarray:
    """The velocity field the thermostat keeps, per particle (N, 3): the centre-of-mass velocity V, plus the
    rigid rotation w x (x - R) about the centre of mass R when ``keep_rotation`` (I w = L; a singular inertia
    tensor, as for a linear arrangement, is solved in the least-squares sense).  v minus this field carries
    zero linear momentum, and zero angular momentum about R when the rotation is kept.  Massless particles
    get the field too but count for nothing."""
    x, v, m = (np.asarray(a, dtype=np.float64) for a in (x, v, m))
    total = m.sum()
    kept = np.broadcast_to(linear_momentum(v, m) / total, v.shape).copy()
    if keep_rotation:
        r = x - centre_of_mass(x, m)
        w = np.linalg.lstsq(inertia_tensor(x, m, about="com"), angular_momentum(x, v, m, about="com"),
                            rcond=None)[0]
        kept += np.cross(w, r)
    return kept


def peculiar_kinetic_energy(x, v, m, keep_rotation: bool) -> float:
    """The kinetic energy (kJ/mol) of the peculiar velocities v - :func:`kept_velocities`: what the thermostat rescales,
    and with its degrees of freedom (:func:`thermostat_dof`) the kinetic temperature 2 K / (N_f R)."""
    v = np.asarray(v, dtype=np.float64)
    return kinetic_energy(v - kept_velocities(x, v, m, keep_rotation), m)
