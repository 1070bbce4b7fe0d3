"""Scene builders: each models no more than the effect it is there to show.

* :func:`water_cluster` -- TIP3P waters in vacuum (no box, no cutoff, no CMMotionRemover), rigid
  (SETTLE) or flexible, spun up about the centre of mass.  Isolated, so energy, linear momentum and
  angular momentum are all conserved quantities; rigid water is enough for rotation, flexible water is
  where large steps fail.
* :func:`morse_molecule` -- a small flexible molecule with Morse bonds and a cosine angle term: nonlinear
  forces in a handful of atoms, the smallest OpenMM system that measures convergence orders.

* :func:`water_box` -- the periodic box of rigid water (PME) that the studies and the bench measure on.
* :func:`harmonic_oscillators` -- independent 3-d harmonic oscillators about the origin in a canonical state: the
  thermostat's known answers (exact stationary temperatures).

Every scene returns a :class:`~.scene.Scene` (system, positions, velocities, topology) built from a seed, so
all runs of a study start from one shared state.
"""
from __future__ import annotations

import numpy as np
import openmm as mm
import openmm.app as app
import openmm.unit as unit

from ..prepare import constrain_velocities, maxwell_boltzmann, minimise
from .scene import Scene
from ...support.errors import InputError

#: TIP3P geometry (nm, radians)
_R_OH = 0.09572
_THETA = np.deg2rad(104.52)


def _water_topology(n):
    top = app.Topology()
    chain = top.addChain()
    O, H = app.element.oxygen, app.element.hydrogen
    for _ in range(n):
        res = top.addResidue("HOH", chain)
        o = top.addAtom("O", O, res)
        h1 = top.addAtom("H1", H, res)
        h2 = top.addAtom("H2", H, res)
        top.addBond(o, h1)
        top.addBond(o, h2)
    return top


def _random_rotation(rng):
    q = rng.normal(size=4)
    q /= np.linalg.norm(q)
    a, b, c, d = q
    return np.array([[a*a + b*b - c*c - d*d, 2*(b*c - a*d), 2*(b*d + a*c)],
                     [2*(b*c + a*d), a*a - b*b + c*c - d*d, 2*(c*d - a*b)],
                     [2*(b*d - a*c), 2*(c*d + a*b), a*a - b*b - c*c + d*d]])


def water_cluster(n_waters: int = 27, rigid: bool = True, temperature: float = 150.0,
                  angular_velocity=(0.0, 0.0, 2.0), spacing: float = 0.31, seed: int = 1,
                  minimize: bool = True) -> Scene:
    """TIP3P waters on a jittered cubic grid in vacuum, rigid (SETTLE) or flexible.

    ``angular_velocity`` (rad/ps) spins the cluster about its centre of mass, so that the angular
    momentum is far from zero and its conservation is a sharp test."""
    if n_waters < 1:
        raise InputError(f"n_waters must be at least 1, got {n_waters}")
    rng = np.random.default_rng(seed)
    side = int(np.ceil(n_waters ** (1 / 3)))
    sites = np.array([(i, j, k) for i in range(side) for j in range(side) for k in range(side)], float)[:n_waters]
    local = np.array([[0.0, 0.0, 0.0],
                      [_R_OH, 0.0, 0.0],
                      [_R_OH * np.cos(_THETA), _R_OH * np.sin(_THETA), 0.0]])
    pos = []
    for s in sites:
        R = _random_rotation(rng)
        centre = s * spacing + rng.uniform(-0.02, 0.02, 3)
        pos.extend(centre + local @ R.T)
    pos = np.array(pos)
    top = _water_topology(n_waters)
    ff = app.ForceField("tip3p.xml")
    system = ff.createSystem(top, nonbondedMethod=app.NoCutoff, constraints=None, rigidWater=rigid,
                             removeCMMotion=False)
    if not rigid:
        _add_flexible_water_terms(system, n_waters)
    if minimize:
        pos = minimise(system, pos, tolerance=1.0)
    vel = maxwell_boltzmann(system, pos, temperature, rng, angular_velocity)
    kind = "rigid (SETTLE)" if rigid else "flexible"
    return Scene(f"water-cluster-{n_waters}{'' if rigid else '-flexible'}", system, np.array(pos), vel,
                 f"{n_waters} {kind} TIP3P waters in vacuum, spinning at {tuple(angular_velocity)} rad/ps", top)


def _add_flexible_water_terms(system, n_waters):
    """Harmonic O-H bonds and H-O-H angle (flexible TIP3P, CHARMM-like constants)."""
    bonds = mm.HarmonicBondForce()
    angles = mm.HarmonicAngleForce()
    for w in range(n_waters):
        o = 3 * w
        bonds.addBond(o, o + 1, _R_OH, 462750.4)
        bonds.addBond(o, o + 2, _R_OH, 462750.4)
        angles.addAngle(o + 1, o, o + 2, _THETA, 836.8)
    system.addForce(bonds)
    system.addForce(angles)


def morse_molecule(seed: int = 3, temperature: float = 300.0, angular_velocity=(0.0, 1.0, 3.0)) -> Scene:
    """A bent 4-atom chain with Morse bonds, cosine angles and a 1-4 Lennard-Jones pair, in vacuum.

    Every force is nonlinear and the molecule is tiny, so a convergence study takes seconds while still
    exercising all the order conditions of a general (nonlinear, several-DOF) problem."""
    rng = np.random.default_rng(seed)
    system = mm.System()
    masses = [12.0, 14.0, 12.0, 16.0]
    for m in masses:
        system.addParticle(m)
    morse = mm.CustomBondForce("D*(1 - exp(-a*(r - r0)))^2")
    for p in ("D", "a", "r0"):
        morse.addPerBondParameter(p)
    for i in range(3):
        morse.addBond(i, i + 1, [400.0, 20.0, 0.15])
    angle = mm.CustomAngleForce("k*(cos(theta) - cos(theta0))^2")
    angle.addPerAngleParameter("k")
    angle.addPerAngleParameter("theta0")
    angle.addAngle(0, 1, 2, [200.0, np.deg2rad(110.0)])
    angle.addAngle(1, 2, 3, [200.0, np.deg2rad(115.0)])
    lj = mm.CustomBondForce("4*eps*((sig/r)^12 - (sig/r)^6)")
    lj.addPerBondParameter("eps")
    lj.addPerBondParameter("sig")
    lj.addBond(0, 3, [0.5, 0.25])
    for f in (morse, angle, lj):
        system.addForce(f)
    top = app.Topology()
    res = top.addResidue("MOL", top.addChain())
    for i, el in enumerate((app.element.carbon, app.element.nitrogen, app.element.carbon, app.element.oxygen)):
        top.addAtom(f"A{i}", el, res)
    pos = np.array([[0.0, 0.0, 0.0], [0.15, 0.0, 0.0], [0.2, 0.14, 0.0], [0.35, 0.16, 0.05]])
    pos += rng.normal(scale=0.005, size=pos.shape)
    vel = maxwell_boltzmann(system, pos, temperature, rng, angular_velocity)
    return Scene("morse-molecule", system, pos, vel, "4-atom Morse chain in vacuum (nonlinear, unconstrained)", top)


def constrained_molecule(seed: int = 3) -> Scene:
    """:func:`morse_molecule` with its three bonds replaced by distance constraints (RATTLE scene)."""
    sc = morse_molecule(seed)
    system = sc.system
    system.removeForce(0)  # the Morse bonds
    for i in range(3):
        d = float(np.linalg.norm(sc.positions[i + 1] - sc.positions[i]))
        system.addConstraint(i, i + 1, d)
    vel = constrain_velocities(system, sc.positions, sc.velocities)
    return Scene("constrained-molecule", system, sc.positions, vel,
                 "4-atom chain with 3 distance constraints, angle and 1-4 terms (nonlinear, constrained)", sc.topology)


def openmm_data(name: str) -> str:
    """The path of a file in OpenMM's bundled data folder (e.g. test.pdb)."""
    import os

    return os.path.join(os.path.dirname(app.__file__), "data", name)


def protein_vacuum(constraints=app.HBonds, temperature: float = 300.0, angular_velocity=(0.0, 0.0, 0.5),
                   seed: int = 5, minimize: bool = True) -> Scene:
    """The villin headpiece from OpenMM's bundled test.pdb, solvent removed, in vacuum (amber14, no
    cutoff, no CMMotionRemover), HBonds constrained by default: a real protein whose conservation
    exercises CCMA constraints, with no periodic box to break rotational symmetry."""
    pdb = app.PDBFile(openmm_data("test.pdb"))
    mod = app.Modeller(pdb.topology, pdb.positions)
    mod.deleteWater()
    mod.delete([r for r in mod.topology.residues() if len(r) == 1])  # counter-ions
    ff = app.ForceField("amber14-all.xml")
    system = ff.createSystem(mod.topology, nonbondedMethod=app.NoCutoff, constraints=constraints,
                             removeCMMotion=False)
    pos = np.array(mod.positions.value_in_unit(unit.nanometer))
    if minimize:
        pos = minimise(system, pos, tolerance=10.0)
    vel = maxwell_boltzmann(system, pos, temperature, seed, angular_velocity)
    return Scene("villin-vacuum", system, np.array(pos), vel,
                 f"villin headpiece (test.pdb, {system.getNumParticles()} atoms) in vacuum, amber14, "
                 f"{system.getNumConstraints()} constraints", mod.topology)


#: Rigid water models for :func:`water_box`: name -> (force field file, Modeller model name).
WATER_MODELS = {"spce": ("amber14/spce.xml", "spce"), "tip3p": ("amber14/tip3p.xml", "tip3p")}


#: Density of liquid water at 298 K and 1 bar, g/cm^3: the default of :func:`water_box`'s ``n_waters`` boxes.
WATER_DENSITY_G_CM3 = 0.997
#: Grams per dalton (1 / Avogadro's number).
_G_PER_DA = 1.66053906660e-24


def water_box(model: str = "spce", n_waters: int | None = None, cutoff_nm: float = 0.9, box_nm: float | None = None,
              ewald_tolerance: float | None = None, forcefields=None,
              density_g_cm3: float | None = WATER_DENSITY_G_CM3):
    """A periodic box of rigid waters (SETTLE), PME with ``cutoff_nm``, no CMMotionRemover (so an NVE run conserves
    the total momentum and the translational degrees of freedom are 3 N - 3): ``n_waters`` molecules (default 216),
    or a cubic box of side ``box_nm``.  ``ewald_tolerance``: OpenMM's ewaldErrorTolerance (default 5e-4);
    ``forcefields``: the force-field files (default the model's own).  The one place a water box is built.

    ``density_g_cm3`` (``n_waters`` boxes): Modeller's ``addSolvent(numAdded=...)`` leaves the box at about
    0.86 g/cm^3 (216 SPC/E waters), so the molecules' centres of mass and the box are scaled about the origin to
    this density (default 0.997 g/cm^3, liquid water at 298 K; None keeps Modeller's box).  Molecules keep their
    shape; a ``box_nm`` box is Modeller's filling of that box, unscaled.
    Returns (system, topology, positions in nm); positions are not minimised."""
    if model not in WATER_MODELS:
        raise InputError(f"unknown water model {model!r}; known: {', '.join(WATER_MODELS)}")
    if box_nm is not None and n_waters is not None:
        raise InputError("give n_waters or box_nm, not both")
    if box_nm is None and n_waters is None:
        n_waters = 216
    if n_waters is not None and (isinstance(n_waters, bool) or int(n_waters) < 2):
        raise InputError(f"n_waters must be >= 2, got {n_waters!r}")
    if density_g_cm3 is not None and (isinstance(density_g_cm3, bool) or not 0 < float(density_g_cm3) < 10):
        raise InputError(f"density_g_cm3 must be a density in g/cm^3 between 0 and 10 (e.g. 0.997), or None for "
                         f"Modeller's own box, got {density_g_cm3!r}")
    ffname, name = WATER_MODELS[model]
    ff = app.ForceField(*(forcefields or (ffname,)))
    mod = app.Modeller(app.Topology(), [])
    if box_nm is not None:
        mod.addSolvent(ff, model=name, boxSize=mm.Vec3(box_nm, box_nm, box_nm) * unit.nanometer)
    else:
        mod.addSolvent(ff, model=name, numAdded=int(n_waters))
    positions = np.array(mod.positions.value_in_unit(unit.nanometer))
    if box_nm is None and density_g_cm3 is not None:
        positions = _scale_to_density(mod.topology, positions, float(density_g_cm3))
    box = min(mod.topology.getUnitCellDimensions().value_in_unit(unit.nanometer))
    if not 2 * cutoff_nm <= box:
        raise InputError(f"cutoff {cutoff_nm} nm needs a box at least {2 * cutoff_nm} nm wide; "
                         f"{f'{n_waters} waters give' if box_nm is None else 'the box is'} {box:.3f} nm: "
                         f"use more waters or a shorter cutoff")
    extra = {} if ewald_tolerance is None else {"ewaldErrorTolerance": ewald_tolerance}
    system = ff.createSystem(mod.topology, nonbondedMethod=app.PME, nonbondedCutoff=cutoff_nm * unit.nanometer,
                             constraints=app.HBonds, rigidWater=True, removeCMMotion=False, **extra)
    return system, mod.topology, positions


def _scale_to_density(topology, positions, density_g_cm3):
    """Scale the cubic box of ``topology`` (set in place) and the residues' centres of mass in ``positions``
    about the origin so that the box's density is ``density_g_cm3``; returns the new positions (nm)."""
    mass = np.array([a.element.mass.value_in_unit(unit.dalton) for a in topology.atoms()])
    edge = float((mass.sum() * _G_PER_DA / density_g_cm3 * 1e21) ** (1.0 / 3.0))  # 1 cm^3 = 1e21 nm^3
    scale = edge / float(topology.getUnitCellDimensions().value_in_unit(unit.nanometer)[0])
    out = positions.copy()
    for res in topology.residues():
        idx = [a.index for a in res.atoms()]
        com = (mass[idx, None] * positions[idx]).sum(axis=0) / mass[idx].sum()
        out[idx] += (scale - 1.0) * com
    topology.setUnitCellDimensions(mm.Vec3(edge, edge, edge) * unit.nanometer)
    return out


def harmonic_oscillators(n: int, k: float, temperature: float, seed: int = 2024):
    """(System, x, v): ``n`` oscillators of mass 1 Da and force constant ``k`` (kJ/mol/nm^2) about the origin,
    canonical positions and velocities at ``temperature`` with the centre of mass at rest at the origin, where it
    stays (the thermostat keeps its velocity; the 3 n - 3 other degrees of freedom are the thermostatted ones)."""
    from ...physics.temperature import R_KJ

    system = mm.System()
    force = mm.CustomExternalForce("0.5*k*(x*x + y*y + z*z)")
    force.addGlobalParameter("k", k)
    for i in range(n):
        system.addParticle(1.0)
        force.addParticle(i, [])
    system.addForce(force)
    rng = np.random.default_rng(seed)
    kT = R_KJ * temperature
    x = rng.normal(0.0, np.sqrt(kT / k), (n, 3))
    v = rng.normal(0.0, np.sqrt(kT), (n, 3))
    return system, x - x.mean(0), v - v.mean(0)
