"""What an openmm.System lets an integrator conserve, and the one-time warnings that say why not."""
from __future__ import annotations

import warnings

import openmm as mm

#: Force classes that act as a thermostat, barostat or velocity editor.
THERMOSTAT_FORCES = ("AndersenThermostat", "MonteCarloBarostat", "MonteCarloAnisotropicBarostat",
                     "MonteCarloMembraneBarostat", "MonteCarloFlexibleBarostat", "RMSDForce")
#: Forces that act like an external field when applied to a subset of particles.
EXTERNAL_FIELD_FORCES = ("CustomExternalForce", "CustomCentroidBondForce")


class ConservationWarning(UserWarning):
    """The system cannot conserve a quantity the user may expect to be conserved."""


def has_constraints(system: mm.System) -> bool:
    return system.getNumConstraints() > 0


def force_names(system: mm.System) -> list:
    return [type(system.getForce(i)).__name__ for i in range(system.getNumForces())]


def conservation_issues(system: mm.System) -> list:
    """Reasons why energy, linear momentum or angular momentum will not be conserved.

    Returns a list of (key, message); empty for an isolated, non-periodic system."""
    issues = []
    names = force_names(system)
    if "CMMotionRemover" in names:
        issues.append(("cmmotionremover",
                       "the System has a CMMotionRemover (ForceField.createSystem adds one unless "
                       "removeCMMotion=False): it zeroes the centre-of-mass velocity every few steps, so "
                       "linear momentum is reset and angular momentum about the origin changes. Remove it "
                       "for conservation studies."))
    if any(system.isVirtualSite(i) for i in range(system.getNumParticles())):
        issues.append(("virtualsites",
                       "the System has virtual sites: OpenMM's CustomIntegrator (8.6) moves them only at the "
                       "end of each step, so forces evaluated inside a step (every kick after a drift) see "
                       "virtual sites one drift behind. Energy and momenta are then conserved only to the "
                       "size of that lag (measured: |dL|/|L| ~ 3e-2 after 400 steps of 8 TIP4P-Ew waters). "
                       "Models without virtual sites (TIP3P, SPC/E) are not affected."))
    if system.usesPeriodicBoundaryConditions():
        issues.append(("periodic",
                       "the System is periodic: periodic boundary conditions break rotational symmetry, "
                       "so angular momentum is not a conserved quantity (linear momentum still is, up to "
                       "force round-off)."))
    for n in names:
        if n in THERMOSTAT_FORCES:
            issues.append((n.lower(), f"the System has a {n}: it exchanges energy (and momentum) with a "
                                      f"bath or rescales the box, so nothing is conserved exactly."))
        elif n in EXTERNAL_FIELD_FORCES:
            issues.append((n.lower(), f"the System has a {n}: an external field or restraint is not "
                                      f"translation/rotation invariant in general, so linear and angular "
                                      f"momentum may change."))
    return issues


_warned: set = set()


def warn_conservation(system: mm.System, context: str = "openmm_symprk", once: bool = True):
    """Emit one ConservationWarning per kind of issue found (once per process per kind)."""
    for key, msg in conservation_issues(system):
        if once and key in _warned:
            continue
        _warned.add(key)
        warnings.warn(f"{context}: {msg}", ConservationWarning, stacklevel=3)



def validate_system(system, context: str, exact_momentum: bool = False, skip=()) -> None:
    """What both integrator backends check of a ``system=`` argument: its type, one warning per kind of
    conservation issue (less the kinds in ``skip``), and exact momentum refused on a periodic system."""
    if not isinstance(system, mm.System):
        raise TypeError(f"system must be an openmm.System, got {type(system).__name__}")
    for key, msg in conservation_issues(system):
        if key in skip or key in _warned:
            continue
        _warned.add(key)
        warnings.warn(f"{context}: {msg}", ConservationWarning, stacklevel=4)
    if exact_momentum and system.usesPeriodicBoundaryConditions():
        raise ValueError(
            "exact_momentum=True removes the net torque of the forces, which is only correct for a "
            "non-periodic (isolated) system; this System is periodic. Use exact_momentum=False.")
