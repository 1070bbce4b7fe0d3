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
    assert (facts.constrained, facts.unconstrained, facts.rigid_waters) == (12, 0, 4)
    assert facts.lightest == pytest.approx(1.008, abs=1e-3)
    facts = hydrogen_facts(flexible)
    assert (facts.constrained, facts.unconstrained, facts.rigid_waters) == (0, 8, 0)


def test_a_protein_with_and_without_hbonds():
    pdb = app.PDBFile(openmm_data("test.pdb"))  # villin in water, with ions
    mod = app.Modeller(pdb.topology, pdb.positions)
    mod.delete([r for r in mod.topology.residues() if r.name == "HOH" or len(list(r.atoms())) == 1])
    ff = app.ForceField("amber14-all.xml")
    n_h = sum(1 for a in mod.topology.atoms() if a.element is app.element.hydrogen)
    none = ff.createSystem(mod.topology, constraints=None)
    hbonds = ff.createSystem(mod.topology, constraints=app.HBonds)
    heavy = ff.createSystem(mod.topology, constraints=app.HBonds, hydrogenMass=4 * unit.amu)
    assert (hydrogen_facts(none).constrained, hydrogen_facts(none).unconstrained) == (0, n_h)
    assert (hydrogen_facts(hbonds).constrained, hydrogen_facts(hbonds).unconstrained) == (n_h, 0)
    assert hydrogen_facts(heavy).constrained == n_h and hydrogen_facts(heavy).lightest == pytest.approx(4.0)


def test_the_hint_names_the_missing_constraints_from_2_fs(clusters):
    rigid, flexible = clusters
    hint = unconstrained_hydrogen_hint(flexible, 4.0)
    assert "8 bond(s) to hydrogen that are not constrained" in hint and "constraints=app.HBonds" in hint
    assert "at 4 fs" in hint
    assert unconstrained_hydrogen_hint(flexible, 2.0) and not unconstrained_hydrogen_hint(flexible, 1.0)
    assert unconstrained_hydrogen_hint(rigid, 4.0) == ""
