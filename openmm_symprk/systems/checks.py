"""What an ``openmm.System`` (and an integrator) lets a simulation conserve, and the one-time warnings that
say why not.

One process-wide registry, :data:`warn_once`, remembers which kinds of warning were given (tests reset it
with ``warn_once.reset()``); every module that warns about conservation goes through it.
"""
from __future__ import annotations

import os
import sys
import warnings

import openmm as mm

from .properties import force_names, frozen_particles, virtual_sites
from ..support.errors import InputError

#: Force classes that act as a thermostat, barostat or velocity editor.
THERMOSTAT_FORCES = ("AndersenThermostat", "MonteCarloBarostat", "MonteCarloAnisotropicBarostat",
                     "MonteCarloMembraneBarostat", "MonteCarloFlexibleBarostat", "RMSDForce")
#: Forces that act like an external field when applied to a subset of particles.
EXTERNAL_FIELD_FORCES = ("CustomExternalForce", "CustomCentroidBondForce")
#: Integrator classes that couple the system to a bath (nothing is conserved).
THERMOSTAT_INTEGRATORS = ("LangevinIntegrator", "LangevinMiddleIntegrator", "BrownianIntegrator",
                          "NoseHooverIntegrator", "VariableLangevinIntegrator", "DPDIntegrator",
                          "DrudeLangevinIntegrator", "DrudeNoseHooverIntegrator", "QTBIntegrator",
                          "RPMDIntegrator")


class ConservationWarning(UserWarning):
    """The system cannot conserve a quantity the user may expect to be conserved."""


_PACKAGE_ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__))) + os.sep


def _outside_caller() -> int:
    """The stacklevel, counted from the caller of WarnOnce.__call__'s warnings.warn, of the first frame whose code
    lies outside the openmm_symprk package (so that a warning names the user's line)."""
    frame, level = sys._getframe(2), 2
    while frame is not None and os.path.abspath(frame.f_code.co_filename).startswith(_PACKAGE_ROOT):
        frame, level = frame.f_back, level + 1
    return level


class WarnOnce:
    """Warn at most once per process for each key."""

    def __init__(self):
        self._seen: set = set()

    def __call__(self, key: str, message: str, category=ConservationWarning, stacklevel: int | None = None) -> bool:
        """Warn once for ``key``.  The warning points at the first caller outside this package (the user's line),
        unless ``stacklevel`` is given."""
        if key in self._seen:
            return False
        self._seen.add(key)
        warnings.warn(message, category, stacklevel=stacklevel + 1 if stacklevel is not None else _outside_caller())
        return True

    def seen(self, key: str) -> bool:
        return key in self._seen

    def reset(self):
        self._seen.clear()


#: The package's one registry of one-time warnings.
warn_once = WarnOnce()


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
    if virtual_sites(system):
        issues.append(("virtualsites",
                       "the System has virtual sites: OpenMM's CustomIntegrator (8.6) places them only at the "
                       "end of each step (and in ConstrainPositions), so forces evaluated inside a step see "
                       "virtual sites one drift behind. Energy and momenta are then conserved only to the size "
                       "of that lag (measured: |dL|/|L| ~ 3e-2 after 400 steps of 8 TIP4P-Ew waters). The "
                       "native backend places them after every drift; models without virtual sites (TIP3P, "
                       "SPC/E) are not affected."))
    frozen = frozen_particles(system)
    if frozen:
        issues.append(("frozen",
                       f"the System has {len(frozen)} massless particle(s) that are not virtual sites (frozen "
                       f"atoms, e.g. particle {frozen[0]}): OpenMM never moves them, so the forces they exert "
                       f"act like an external field and linear and angular momentum are not conserved."))
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


def integrator_issues(integrator) -> list:
    """(key, message) for integrators that cannot conserve energy or momentum (thermostats)."""
    name = type(integrator).__name__
    if name in THERMOSTAT_INTEGRATORS:
        return [(name.lower(), f"the integrator is a {name}: it couples the system to a heat bath (friction "
                               f"and random forces), so energy and momentum are not conserved.")]
    return []


def warn_conservation(system: mm.System, context: str = "openmm_symprk", skip=(), stacklevel: int | None = None) -> list:
    """One ConservationWarning per kind of issue found (once per process per kind); returns the issues."""
    issues = conservation_issues(system)
    for key, msg in issues:
        if key not in skip:
            warn_once(key, f"{context}: {msg}", stacklevel=stacklevel)
    return issues


#: Issue kinds under which exact_momentum=True would change the exact dynamics: the projection removes
#: the net force and torque, which are only zero for an isolated system.
EXACT_MOMENTUM_FORBIDDEN = ("periodic", "frozen", *(n.lower() for n in EXTERNAL_FIELD_FORCES))


def check_system_type(system) -> None:
    """TypeError unless ``system`` is an openmm.System (naming what it got, and ``.system`` where it has one)."""
    if not isinstance(system, mm.System):
        hint = (" (it has one: pass its .system)" if isinstance(getattr(system, "system", None), mm.System)
                else "")
        raise TypeError(f"system must be an openmm.System, got {type(system).__name__}{hint}")


#: Issue kinds that say what a run gets wrong, not what it fails to conserve: warned whatever the run asked for.
ALWAYS_WARNED = ("virtualsites",)
#: Issue kinds that break the conservation of energy: warned in NVE, where energy is what the run conserves.
ENERGY_ISSUES = tuple(n.lower() for n in THERMOSTAT_FORCES)


def asked_for(system: mm.System, exact_momentum: bool = False, thermostat: bool = False):
    """The kinds of issue (of :func:`conservation_issues`) that break what a run conserves, so that its integrator warns
    about them: None (every kind) with ``exact_momentum`` or in an NVE run of a System that is not periodic, where
    energy and momenta are what the run is for; in an NVE run of a periodic System the kinds that break the energy (a
    barostat or thermostat force); in an NVT run (``thermostat``) none.  :data:`ALWAYS_WARNED` kinds are warned in
    every run."""
    if exact_momentum or (not thermostat and not system.usesPeriodicBoundaryConditions()):
        return None
    return ALWAYS_WARNED + (() if thermostat else ENERGY_ISSUES)


def validate_system(system, context: str, exact_momentum: bool = False, skip=(), thermostat: bool = False) -> None:
    """What every integrator checks of its ``system=``: its type, one warning per kind of conservation issue its run
    asks about (:func:`asked_for`: a periodic NVT run, ``thermostat``, gets none about its CMMotionRemover or its box),
    less the kinds in ``skip``, and exact momentum refused where the System is not isolated."""
    check_system_type(system)
    issues = conservation_issues(system)
    wanted = asked_for(system, exact_momentum, thermostat)
    for key, msg in issues:
        if (wanted is None or key in wanted) and key not in skip:
            warn_once(key, f"{context}: {msg}")
    if exact_momentum:
        bad = [msg for key, msg in issues if key in EXACT_MOMENTUM_FORBIDDEN]
        if bad:
            raise InputError(
                "exact_momentum=True removes the net force and torque of every kick, which is only correct for "
                "an isolated System (no periodic box, no frozen particles, no external field); here "
                + " Also, ".join(bad) + " Use exact_momentum=False.")
