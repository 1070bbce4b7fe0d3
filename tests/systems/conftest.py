"""Small hand-built Systems whose facts (particles, constraints, virtual sites, molecules) are known by hand."""
import types

import numpy as np
import openmm as mm
import openmm.app as app
import pytest

#: TIP4P-Ew: O-H, H-O-H, and the massless M site as a weighted average of O, H, H.
R_OH, THETA, M_WEIGHTS = 0.09572, np.deg2rad(104.52), (0.786646558, 0.106676721, 0.106676721)


class Built:
    """A System with positions (nm) and a Topology of one residue per molecule."""

    def __init__(self, system, positions, residues):
        self.system, self.positions = system, np.asarray(positions, dtype=float)
        self.topology = app.Topology()
        chain = self.topology.addChain()
        for atoms, bonds in residues:
            res = self.topology.addResidue("MOL", chain)
            made = [self.topology.addAtom(name, app.element.Element.getBySymbol(el) if el else None, res)
                    for name, el in atoms]
            for a, b in bonds:
                self.topology.addBond(made[a], made[b])

    def context(self, integrator=None):
        ctx = mm.Context(self.system, integrator or mm.VerletIntegrator(0.001),
                         mm.Platform.getPlatformByName("Reference"))
        ctx.setPositions(self.positions)
        ctx.computeVirtualSites()
        return ctx


def tip4p_waters(n: int, spacing: float = 0.35) -> Built:
    """``n`` rigid 4-site waters (O, H, H with 3 constraints, and a massless virtual site M), no forces."""
    system = mm.System()
    positions, residues = [], []
    local = np.array([[0, 0, 0], [R_OH, 0, 0], [R_OH * np.cos(THETA), R_OH * np.sin(THETA), 0]])
    for w in range(n):
        o = 4 * w
        for mass in (15.99943, 1.007947, 1.007947, 0.0):
            system.addParticle(mass)
        system.setVirtualSite(o + 3, mm.ThreeParticleAverageSite(o, o + 1, o + 2, *M_WEIGHTS))
        r_hh = float(np.linalg.norm(local[1] - local[2]))
        system.addConstraint(o, o + 1, R_OH)
        system.addConstraint(o, o + 2, R_OH)
        system.addConstraint(o + 1, o + 2, r_hh)
        xyz = local + np.array([w * spacing, 0.1 * w, 0.0])
        positions.extend([*xyz, np.asarray(M_WEIGHTS) @ xyz])
        residues.append(([("O", "O"), ("H1", "H"), ("H2", "H"), ("M", None)], [(0, 1), (0, 2)]))
    return Built(system, positions, residues)


def chain(masses=(12.0, 14.0, 12.0, 16.0, 1.0), constraints=(), seed: int = 0) -> Built:
    """Particles on a zig-zag line, bonded by harmonic bonds between neighbours (except massless ones, which
    have no bonds), optionally with distance constraints between the listed pairs (at their initial distance)."""
    rng = np.random.default_rng(seed)
    system = mm.System()
    for m in masses:
        system.addParticle(m)
    x = np.array([[0.15 * i, 0.05 * (i % 2), 0.0] for i in range(len(masses))]) + rng.normal(0, 0.003, (len(masses), 3))
    bonds = mm.HarmonicBondForce()
    pairs = [(i, i + 1) for i in range(len(masses) - 1) if masses[i] > 0 and masses[i + 1] > 0]
    for i, j in pairs:
        bonds.addBond(i, j, 0.15, 1.0e5)
    system.addForce(bonds)
    for i, j in constraints:
        system.addConstraint(i, j, float(np.linalg.norm(x[i] - x[j])))
    return Built(system, x, [([(f"A{i}", "C") for i in range(len(masses))], pairs)])


@pytest.fixture
def build():
    """The builders, for tests: ``build.tip4p_waters(n)``, ``build.chain(masses, constraints)``."""
    return types.SimpleNamespace(tip4p_waters=tip4p_waters, chain=chain)
