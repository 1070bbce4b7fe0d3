"""Force groups for multiple time stepping: which forces of a System are in which group, checks of a
``groups=`` specification against them, and a helper that puts the forces into the usual groups.

    groups = split_forces(system, slow="reciprocal", substeps=2)   # PME reciprocal space every outer step
    integrator = SymplecticIntegrator(4*unit.femtoseconds, "verlet", system=system, groups=groups)
"""
from __future__ import annotations

import openmm as mm

from ..support.errors import InputError

__all__ = ["force_groups", "check_groups", "split_forces", "NONBONDED_FORCES"]

#: Forces that act between non-bonded pairs (the slow group of ``split_forces(slow="nonbonded")``).
NONBONDED_FORCES = ("NonbondedForce", "CustomNonbondedForce", "GBSAOBCForce", "CustomGBForce",
                    "AmoebaMultipoleForce", "AmoebaVdwForce", "AmoebaGeneralizedKirkwoodForce",
                    "AmoebaWcaDispersionForce", "HippoNonbondedForce")
#: Forces that are not forces on the dynamics (integrator helpers, barostats): they belong to no group.
NOT_FORCES = ("CMMotionRemover", "AndersenThermostat", "MonteCarloBarostat", "MonteCarloAnisotropicBarostat",
              "MonteCarloMembraneBarostat", "MonteCarloFlexibleBarostat")


def force_groups(system: mm.System) -> dict:
    """{force group: [names of the forces (or force parts) in it]}; a NonbondedForce with its reciprocal space in
    another group appears in both, as "NonbondedForce (reciprocal space)" in the second."""
    out: dict = {}
    for i in range(system.getNumForces()):
        f = system.getForce(i)
        name = type(f).__name__
        if name in NOT_FORCES:
            continue
        out.setdefault(f.getForceGroup(), []).append(f"{name} #{i}")
        if isinstance(f, mm.NonbondedForce) and f.getReciprocalSpaceForceGroup() >= 0 and \
                f.getNonbondedMethod() in (mm.NonbondedForce.PME, mm.NonbondedForce.LJPME, mm.NonbondedForce.Ewald):
            out.setdefault(f.getReciprocalSpaceForceGroup(), []).append(f"{name} #{i} (reciprocal space)")
    return out


def check_groups(system: mm.System, groups) -> None:
    """ValueError unless every force of ``system`` is in a group of ``groups`` ([(group, substeps), ...]) and
    every group there holds some force."""
    present = force_groups(system)
    wanted = {g for g, _ in groups}
    uncovered = {g: names for g, names in present.items() if g not in wanted}
    if uncovered:
        what = "; ".join(f"group {g}: {', '.join(names)}" for g, names in sorted(uncovered.items()))
        raise InputError(f"groups={list(groups)} leaves forces out ({what}): every force group of the System needs a "
                         f"(group, substeps) entry, or those forces would never act")
    empty = sorted(wanted - set(present))
    if empty:
        have = "; ".join(f"group {g}: {', '.join(n)}" for g, n in sorted(present.items()))
        raise InputError(f"force group(s) {', '.join(map(str, empty))} of groups={list(groups)} hold no force of the "
                         f"System (its groups: {have})")


def split_forces(system: mm.System, slow="reciprocal", substeps: int = 2, fast_group: int = 0,
                 slow_group: int = 1) -> list:
    """Put the System's forces into a fast and a slow force group (in place) and return the ``groups=`` argument
    ``[(slow_group, 1), (fast_group, substeps)]``: the slow forces once per outer step, the fast ones
    ``substeps`` times.

    ``slow``: "reciprocal" -- the reciprocal space of PME/Ewald (the usual choice: smooth, and on GPUs the
    costly part); "nonbonded" -- every non-bonded force (bonded terms fast); or a list of Force class names
    or force indices."""
    if isinstance(substeps, bool) or not isinstance(substeps, int) or substeps < 1:
        raise InputError(f"substeps must be a whole number >= 1, got {substeps!r}")
    if fast_group == slow_group or not (0 <= fast_group <= 31 and 0 <= slow_group <= 31):
        raise InputError(f"fast_group and slow_group must be two different groups from 0 to 31, got "
                         f"{fast_group} and {slow_group}")
    forces = [system.getForce(i) for i in range(system.getNumForces())]
    if slow == "reciprocal":
        pme = [f for f in forces if isinstance(f, mm.NonbondedForce) and f.getNonbondedMethod() in
               (mm.NonbondedForce.PME, mm.NonbondedForce.LJPME, mm.NonbondedForce.Ewald)]
        if not pme:
            raise InputError("slow='reciprocal' needs a NonbondedForce with PME, LJPME or Ewald (this System has no "
                             "reciprocal space); use slow='nonbonded' or name the slow forces")
        for f in forces:
            f.setForceGroup(fast_group)
        for f in pme:
            f.setReciprocalSpaceForceGroup(slow_group)
    else:
        if slow == "nonbonded":
            is_slow = [type(f).__name__ in NONBONDED_FORCES for f in forces]
        else:
            try:
                names = list(slow)
            except TypeError:
                raise InputError(f"slow must be 'reciprocal', 'nonbonded' or a list of Force names or indices, "
                                 f"got {slow!r}") from None
            known = {type(f).__name__ for f in forces}
            bad = [n for n in names if not (isinstance(n, int) and 0 <= n < len(forces)) and n not in known]
            if bad:
                raise InputError(f"slow forces {bad} are not in the System (it has {', '.join(sorted(known))}; "
                                 f"or give indices 0-{len(forces) - 1})")
            is_slow = [i in names or type(f).__name__ in names for i, f in enumerate(forces)]
        if not any(s and type(f).__name__ not in NOT_FORCES for f, s in zip(forces, is_slow)):
            raise InputError(f"no force of the System is slow under slow={slow!r} ({', '.join(NOT_FORCES[:2])} and "
                             f"barostats are not forces on the dynamics and belong to no group)")
        for f, s in zip(forces, is_slow):
            f.setForceGroup(slow_group if s else fast_group)
            if isinstance(f, mm.NonbondedForce):
                f.setReciprocalSpaceForceGroup(-1)  # follows the force's own group
        if all(is_slow[i] for i, f in enumerate(forces) if type(f).__name__ not in NOT_FORCES):
            raise InputError(f"every force of the System is slow under slow={slow!r}: nothing is left for the inner "
                             f"steps")
    return [(slow_group, 1), (fast_group, substeps)]
