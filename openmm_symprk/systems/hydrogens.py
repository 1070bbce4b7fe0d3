"""What a System does with its hydrogens, read from the System alone (no Topology): the bonds to hydrogen it
constrains and the ones it leaves to vibrate, and its rigid waters.  The step a System allows depends on them: an
unconstrained bond to hydrogen vibrates with a period of about 9-11 fs, which Verlet cannot follow beyond about 2 fs.

A bond is a HarmonicBondForce or CustomBondForce bond or a constraint; a hydrogen is a particle of mass up to
:data:`HYDROGEN_MAX_MASS` (hydrogen, deuterium, and the 1.5-4 Da hydrogens of mass repartitioning) with at most two
bonds (one, or a rigid water's two: to its oxygen and its partner hydrogen), so that a methyl carbon that
repartitioning to 4 Da leaves at 3 Da, with four bonds, is not one.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import openmm as mm

from .properties import masses

__all__ = ["HYDROGEN_MAX_MASS", "HydrogenFacts", "hydrogen_facts", "UNCONSTRAINED_HYDROGEN_STEP_FS", "unconstrained_hydrogen_hint"]

#: The largest mass (Da) counted as a hydrogen: hydrogen (1.008), deuterium, repartitioned hydrogens (1.5-4 Da).
HYDROGEN_MAX_MASS = 4.5


@dataclass(frozen=True)
class HydrogenFacts:
    """``constrained``: bonds to a hydrogen that are constraints (a rigid water's three among them); ``unconstrained``:
    bonds to a hydrogen (bond forces) without a constraint between the same two particles; ``rigid_waters``:
    three-particle molecules (one heavy atom, two hydrogens) held by three constraints; ``solute_constrained``: the
    constrained bonds to hydrogen outside rigid waters (HBonds of a solute); ``solute_hydrogen_mass``: the smallest
    mass (Da) of a hydrogen outside rigid waters (0 without one; 1.5-4 after mass repartitioning, which leaves water's
    hydrogens alone)."""

    constrained: int
    unconstrained: int
    rigid_waters: int
    solute_constrained: int
    solute_hydrogen_mass: float


def _bond_pairs(system: mm.System):
    for force in system.getForces():
        if isinstance(force, (mm.HarmonicBondForce, mm.CustomBondForce)):
            for k in range(force.getNumBonds()):
                p = force.getBondParameters(k)
                yield int(p[0]), int(p[1])


def _rigid_waters(constraints, hydrogen) -> list:
    """The (heavy atom, hydrogen, hydrogen) triples that three constraints hold together and to nothing else."""
    partners: dict = {}
    for pair in constraints:
        for i in pair:
            partners.setdefault(i, set()).update(pair - {i})
    waters = []
    for heavy, bound in partners.items():
        if hydrogen[heavy] or len(bound) != 2 or not all(hydrogen[h] for h in bound):
            continue
        h1, h2 = bound
        if partners.get(h1, set()) == {heavy, h2} and partners.get(h2, set()) == {heavy, h1}:
            waters.append((heavy, h1, h2))
    return waters


def hydrogen_facts(system: mm.System) -> HydrogenFacts:
    """The :class:`HydrogenFacts` of ``system``."""
    m = masses(system)
    constraints = {frozenset((int(i), int(j))) for i, j, _ in
                   (system.getConstraintParameters(k) for k in range(system.getNumConstraints()))}
    bonds = {frozenset(pair) for pair in _bond_pairs(system) if pair[0] != pair[1]}
    degree = np.zeros(len(m), dtype=int)
    for pair in bonds | constraints:
        for i in pair:
            degree[i] += 1
    hydrogen = (m > 0) & (m <= HYDROGEN_MAX_MASS) & (degree <= 2)
    constrained = sum(1 for pair in constraints if any(hydrogen[i] for i in pair))
    unconstrained = {pair for pair in bonds if any(hydrogen[i] for i in pair)} - constraints
    waters = _rigid_waters(constraints, hydrogen)
    solute = hydrogen.copy()
    solute[[i for water in waters for i in water[1:]]] = False
    return HydrogenFacts(constrained, len(unconstrained), len(waters), constrained - 3 * len(waters),
                         float(m[solute].min()) if solute.any() else 0.0)


#: From this step (fs) on, a bond to hydrogen left to vibrate is the usual cause of a blow-up: its period of about 9-11
#: fs puts h*omega at 1.1-1.4 for 2 fs (Verlet's limit is 2, a fourth-order composition's 1.57).
UNCONSTRAINED_HYDROGEN_STEP_FS = 2.0


def unconstrained_hydrogen_hint(system: mm.System, step_fs: float) -> str:
    """A sentence for a blow-up at ``step_fs`` of a System that leaves bonds to hydrogen unconstrained ("" if it does
    not, or the step is below :data:`UNCONSTRAINED_HYDROGEN_STEP_FS`)."""
    if step_fs < UNCONSTRAINED_HYDROGEN_STEP_FS - 1e-9:
        return ""
    facts = hydrogen_facts(system)
    if not facts.unconstrained:
        return ""
    return (f" The System has {facts.unconstrained} bond(s) to hydrogen that are not constrained: their vibration "
            f"(a period of about 9-11 fs) cannot be followed at {step_fs:g} fs. Create the System with "
            f"constraints=app.HBonds (ForceField.createSystem; rigidWater=True, the default, for water), as "
            f"production runs at 2 fs and more do, or take a step of about 1 fs.")
