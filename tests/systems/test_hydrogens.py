"""The bonds to hydrogen a System constrains or leaves to vibrate, and its rigid waters, read from the System alone."""
import openmm as mm
import openmm.app as app
import openmm.unit as unit
import pytest

from openmm_symprk.systems.hydrogens import hydrogen_facts, unconstrained_hydrogen_hint
from openmm_symprk.systems.scenes import openmm_data, water_cluster


@pytest.fixture(scope="module")
def clusters():
    return water_cluster(4, minimize=False).system, water_cluster(4, rigid=False, minimize=False).system


def test_rigid_and_flexible_water(clusters):
    rigid, flexible = clusters
    facts = hydrogen_facts(rigid)
    assert (facts.constrained, facts.unconstrained, facts.rigid_waters, facts.solute_constrained) == (12, 0, 4, 0)
    assert facts.solute_hydrogen_mass == 0
    facts = hydrogen_facts(flexible)
    assert (facts.constrained, facts.unconstrained, facts.rigid_waters) == (0, 8, 0)
    assert facts.solute_hydrogen_mass == pytest.approx(1.008, abs=1e-3)  # (no rigid water: every hydrogen counts)


def test_a_solvated_protein_with_and_without_hbonds_and_hmr():
    pdb = app.PDBFile(openmm_data("test.pdb"))  # villin in water, with a chloride ion
    ff = app.ForceField("amber14-all.xml", "amber14/tip3p.xml")
    waters = sum(1 for r in pdb.topology.residues() if r.name == "HOH")
    n_h = sum(1 for a in pdb.topology.atoms() if a.element is app.element.hydrogen) - 2 * waters
    none = hydrogen_facts(ff.createSystem(pdb.topology, constraints=None, rigidWater=False))
    hbonds = hydrogen_facts(ff.createSystem(pdb.topology, constraints=app.HBonds))
    hmr = hydrogen_facts(ff.createSystem(pdb.topology, constraints=app.HBonds, hydrogenMass=4 * unit.amu))
    assert (none.constrained, none.unconstrained, none.rigid_waters) == (0, n_h + 2 * waters, 0)
    assert (hbonds.solute_constrained, hbonds.unconstrained, hbonds.rigid_waters) == (n_h, 0, waters)
    assert hbonds.solute_hydrogen_mass == pytest.approx(1.008, abs=1e-3)
    # (a methyl carbon left at 3 Da by repartitioning to 4 Da has four bonds: it is not taken for a hydrogen)
    assert (hmr.solute_constrained, hmr.rigid_waters, hmr.solute_hydrogen_mass) == (n_h, waters, pytest.approx(4.0))


def test_the_hint_names_the_missing_constraints_from_2_fs(clusters):
    rigid, flexible = clusters
    hint = unconstrained_hydrogen_hint(flexible, 4.0)
    assert "8 bond(s) to hydrogen that are not constrained" in hint and "constraints=app.HBonds" in hint
    assert "at 4 fs" in hint
    assert unconstrained_hydrogen_hint(flexible, 2.0) and not unconstrained_hydrogen_hint(flexible, 1.0)
    assert unconstrained_hydrogen_hint(rigid, 4.0) == ""
