"""The named scenes of the bench and the studies: each models no more than the question it answers.

A scene (:class:`openmm_symprk.systems.scenes.Scene`, the package's one scene type) is a System plus one shared
initial state (positions and velocities, nm and nm/ps) and what may be measured on it: which quantities are
invariants, whether an exact solution exists, whether it is for accuracy, speed or production-shaped runs.  A study
builds its scenes once, stores them in its output folder (:func:`~openmm_symprk.systems.scenes.save_scene`, or with
their replica states, :mod:`.replicas`) and ships them to the workers as a
:meth:`~openmm_symprk.systems.scenes.Scene.payload`, so every run (and every run of a resumed study) starts from
bit-identical coordinates.

``SCENES`` maps the names to their builders; each builder's docstring says why its model is enough for its
question and no more.  :func:`user_scene` wraps a System of your own.
"""
from __future__ import annotations

import warnings

import numpy as np
import openmm as mm
import openmm.app as app
import openmm.unit as unit

from ...systems.forcegroups import split_forces
from ...systems.prepare import equilibrate, maxwell_boltzmann, minimise
from ...systems.repartition import repartition_hydrogen_mass
from ...systems.scenes import Scene, openmm_data, protein_vacuum, water_box, water_cluster
from ...support.errors import InputError

__all__ = ["SCENES", "build", "user_scene"]


def _why(fn) -> str:
    return " ".join((fn.__doc__ or "").split())


# -- the analytic toys ---------------------------------------------------------------------------
def harmonic(n: int = 256, omega_max: float | None = None, seed: int = 11) -> Scene:
    """Independent harmonic oscillators, frequencies spread evenly up to an O-H stretch (700/ps).

    Linear forces have an exact solution, so every error is the integrator's own; a spectrum reaching
    down to zero is enough to turn "largest stable step" into the linear stability interval (stable for
    every h*omega up to the limit), and nothing else is needed for that question.  External wells:
    energy and angular momentum about the origin are invariants, linear momentum is not."""
    from . import toys

    omega_max = toys.OMEGA_OH if omega_max is None else omega_max
    omega = toys.harmonic_frequencies(n, omega_max)
    x0, v0 = toys.harmonic_initial_state(omega, seed)
    return Scene("harmonic", toys.harmonic_system(omega), x0, v0,
                      f"{n} harmonic oscillators, omega up to {omega_max:g}/ps (exact solution)",
                      invariants=("energy", "angular_momentum"),
                      exact={"toy": "harmonic", "omega": omega, "x0": x0, "v0": v0},
                      linear={"omega_max": float(omega_max)}, why=_why(harmonic))


def anharmonic(n: int = 64, seed: int = 13) -> Scene:
    """Independent hardening Duffing oscillators (quartic term as large as the quadratic one).

    Nonlinear forces reach the order conditions that a harmonic force cannot see (on q'' = -q every
    consistent splitting of a given symmetric structure looks alike), and the cn-function solution keeps
    the answer exact.  Separable quartic wells: energy is the only invariant."""
    from . import toys

    a, b, amp = toys.duffing_parameters(n)
    x0, v0, u0 = toys.duffing_initial_state(a, b, amp, seed)
    return Scene("anharmonic", toys.duffing_system(a, b), x0, v0,
                      f"{n} Duffing oscillators (x 3 axes), frequencies up to ~700/ps (exact solution)",
                      invariants=("energy",), exact={"toy": "duffing", "a": a, "b": b, "amp": amp, "u0": u0},
                      why=_why(anharmonic))


# -- molecular scenes (built from the core scenes) -----------------------------------------------
def _from_core(scene, name, why, **kw) -> Scene:
    return Scene(name, scene.system, np.array(scene.positions), np.array(scene.velocities), scene.description,
                      why=why, **kw)


def water_rigid(n_waters: int = 64) -> Scene:
    """A spinning cluster of rigid TIP3P waters in vacuum (SETTLE, no cutoff, no CMMotionRemover).

    Rigid water is the common production model; with SETTLE the fastest motion left is libration, so
    this is where 2-4 fs steps are used.  In vacuum, without a box, energy, linear momentum and angular
    momentum are all invariants; a cluster of 64 molecules has a liquid-like local structure and costs
    little on the Reference platform."""
    return _from_core(water_cluster(n_waters, rigid=True), "water-rigid", _why(water_rigid))


def water_flexible(n_waters: int = 64) -> Scene:
    """The same cluster with flexible waters (harmonic O-H bonds and H-O-H angle, no constraints).

    The O-H stretch (period about 9 fs) is the fastest motion in biomolecular MD: this is where large
    steps fail and where the stability of a method per force evaluation decides what step it can take."""
    return _from_core(water_cluster(n_waters, rigid=False), "water-flexible", _why(water_flexible))


def villin() -> Scene:
    """The villin headpiece (OpenMM's bundled test.pdb) in vacuum, amber14, HBonds constraints (CCMA).

    A real protein: torsions, 1-4 terms and a few hundred constraints solved iteratively (CCMA at
    tolerance 1e-10), the case where compositions keep their order under constraints and other
    splittings drop to order 2.  Vacuum and no cutoff keep every invariant and the cost at a few ms per
    force evaluation on the Reference platform; solvent would only add cost here."""
    return _from_core(protein_vacuum(), "villin", _why(villin))


def villin_vacuum_hmr(hydrogen_mass: float = 1.5) -> Scene:
    """Villin in vacuum (:func:`villin`) with the hydrogen masses repartitioned to 1.5 Da: the seconds-long stand-in of
    ``villin-pme-hmr`` in quick drift studies."""
    sc = protein_vacuum()
    system = repartition_hydrogen_mass(sc.system, sc.topology, hydrogen_mass)
    return Scene("villin-vacuum-hmr", system, np.array(sc.positions), np.array(sc.velocities),
                 sc.description + f", HMR {hydrogen_mass:g} Da", sc.topology, why=_why(villin_vacuum_hmr))


def water_box_216(seed: int = 3) -> Scene:
    """216 rigid TIP3P waters in a periodic box (648 atoms), PME with a 0.9 nm cutoff, minimised, velocities at
    300 K: the NVT drift study's box (a study's replica states start from it, :mod:`.replicas`), small enough that
    20-ps runs take minutes on the CPU platform."""
    system, topology, x = water_box("tip3p", n_waters=216, cutoff_nm=0.9)
    pos = minimise(system, x, "CPU", tolerance=10.0, max_iterations=200)
    return Scene("water-box-216", system, pos, maxwell_boltzmann(system, pos, 300.0, seed),
                 f"216 rigid TIP3P waters, PME 0.9 nm, {system.getNumParticles()} atoms, periodic", topology,
                 purpose="production", platform="CPU", invariants=("energy", "momentum"), why=_why(water_box_216))


def water_box_pme(box_nm: float = 3.9, seed: int = 17) -> Scene:
    """A periodic box of rigid TIP3P water (~5800 atoms), PME, 0.9 nm cutoff: speed only.

    This is the shape of a production run, so it is what the wall-time ratios to VerletIntegrator are
    measured on (CPU platform).  Periodic boxes break rotational symmetry and the PME grid makes the
    energy approximate, so no accuracy or stability figure is taken here: the other scenes answer those."""
    system, _, x = water_box("tip3p", box_nm=box_nm, cutoff_nm=0.9, forcefields=("amber14-all.xml", "amber14/tip3p.xml"))
    pos = minimise(system, x, "CPU", tolerance=10.0, max_iterations=100)
    vel = maxwell_boltzmann(system, pos, 300.0, seed)
    return Scene("water-box-pme", system, pos, vel,
                      f"periodic TIP3P box, {system.getNumParticles()} atoms, PME (speed only)",
                      purpose="speed", platform="CPU", invariants=("energy", "momentum"), why=_why(water_box_pme))


def villin_pme(hmr: bool = False, equilibrate_ps: float = 10.0, seed: int = 29) -> Scene:
    """OpenMM's test.pdb as shipped: the villin headpiece in 2,761 TIP3P waters (8,867 atoms), amber14, PME with a
    0.9 nm cutoff, HBonds and rigid water, no CMMotionRemover; with ``hmr`` the hydrogen masses are repartitioned
    to 1.5 Da (ForceField hydrogenMass).  NVE from one Langevin-equilibrated state at 300 K.

    This is the run OpenMM users make, so it is where "what should I run" is answered: energy drift (kT/ns/DOF,
    the unit of OpenMM's published validation), energy fluctuation per DOF and ns/day, against OpenMM's
    VerletIntegrator on the same masses.  The reciprocal space of PME is in force group 1 (all else in group 0),
    for the multiple-time-step rows; the single-level rows integrate both groups."""
    pdb = app.PDBFile(openmm_data("test.pdb"))
    ff = app.ForceField("amber14-all.xml", "amber14/tip3p.xml")
    system = ff.createSystem(pdb.topology, nonbondedMethod=app.PME, nonbondedCutoff=0.9 * unit.nanometer,
                             constraints=app.HBonds, rigidWater=True, removeCMMotion=False,
                             hydrogenMass=1.5 * unit.amu if hmr else None)
    split_forces(system, slow="reciprocal")
    pos = minimise(system, pdb.positions, "CPU", tolerance=10.0, max_iterations=200)
    pos, vel = equilibrate(system, pos, 300.0, equilibrate_ps, seed)
    return Scene("villin-pme-hmr" if hmr else "villin-pme", system, pos, vel,
                      f"villin in water (test.pdb, {system.getNumParticles()} atoms), PME 0.9 nm, HBonds, rigid water"
                      + (", HMR 1.5 Da" if hmr else "") + f", equilibrated {equilibrate_ps:g} ps at 300 K",
                      purpose="production", platform="CPU", invariants=("energy",), why=_why(villin_pme))


def water_pme_accurate(box_nm: float = 3.0, ewald_tolerance: float = 1e-6, equilibrate_ps: float = 5.0,
                       seed: int = 31) -> Scene:
    """A rigid TIP3P box (about 2,700 atoms) with PME tuned for accuracy (ewaldErrorTolerance 1e-6: a 128^3 grid
    on 3 nm): the reciprocal space costs about twice the rest on the CPU platform, so it models the expensive,
    smooth long-range force a user puts on the outer step of multiple time stepping (accurate electrostatics,
    or a machine-learned or polarizable term).  It is where multiple time stepping pays."""
    system, _, x = water_box("tip3p", box_nm=box_nm, cutoff_nm=0.9, ewald_tolerance=ewald_tolerance)
    split_forces(system, slow="reciprocal")
    pos = minimise(system, x, "CPU", tolerance=10.0, max_iterations=200)
    pos, vel = equilibrate(system, pos, 300.0, equilibrate_ps, seed)
    return Scene("water-pme-accurate", system, pos, vel,
                      f"rigid TIP3P box, {system.getNumParticles()} atoms, PME with ewaldErrorTolerance "
                      f"{ewald_tolerance:g} (reciprocal space in group 1)", purpose="production", platform="CPU",
                      invariants=("energy",), why=_why(water_pme_accurate))


#: Registry: name -> builder.  Default sweeps use all of them.
SCENES = {
    "harmonic": harmonic,
    "anharmonic": anharmonic,
    "water-rigid": water_rigid,
    "water-flexible": water_flexible,
    "villin": villin,
    "villin-vacuum": villin,
    "villin-vacuum-hmr": villin_vacuum_hmr,
    "water-box-216": water_box_216,
    "water-box-pme": water_box_pme,
    "villin-pme": villin_pme,
    "villin-pme-hmr": lambda **kw: villin_pme(hmr=True, **kw),
    "water-pme-accurate": water_pme_accurate,
}


def build(name: str, **params) -> Scene:
    try:
        builder = SCENES[name]
    except KeyError:
        raise InputError(f"unknown bench scene {name!r}; known: {', '.join(SCENES)} "
                         f"(or pass your own System with --system-xml/--pdb)") from None
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return builder(**params)


# -- helpers and user scenes ---------------------------------------------------------------------
def _invariants_of(system) -> tuple:
    from ...systems.checks import conservation_issues

    keys = {k for k, _ in conservation_issues(system)}
    inv = []
    if not keys - {"periodic", "cmmotionremover"}:
        inv.append("energy")
    if not keys - {"periodic"}:
        inv.append("momentum")
    if not keys:
        inv.append("angular_momentum")
    return tuple(inv)


def user_scene(name: str = "user", system_xml: str | None = None, state: str | None = None,
               pdb: str | None = None, forcefields=(), temperature: float = 300.0, seed: int = 23,
               platform: str | None = None, minimize: bool = True, equilibrate_ps: float = 2.0) -> Scene:
    """Your own system: a serialized System XML with positions (PDB or serialized State XML), or a PDB
    plus force-field file names (e.g. ``amber14-all.xml amber14/tip3pfb.xml``).

    PDB + force fields are built with no cutoff in vacuum and PME with a box, HBonds constraints and no
    CMMotionRemover.  Velocities come from the State XML if it has them, else Maxwell-Boltzmann at
    ``temperature`` (seeded).  Which invariants are reported follows the System (periodic boxes, motion
    removers and thermostats remove them); the default platform is Reference without a box, CPU with one."""
    velocities = None
    if system_xml:
        with open(system_xml) as fh:
            system = mm.XmlSerializer.deserialize(fh.read())
        if state and state.endswith(".xml"):
            with open(state) as fh:
                st = mm.XmlSerializer.deserialize(fh.read())
            positions = np.array(st.getPositions(asNumpy=True).value_in_unit(unit.nanometer))
            try:
                velocities = np.array(st.getVelocities(asNumpy=True).value_in_unit(unit.nanometer / unit.picosecond))
                if not np.any(velocities):
                    velocities = None
            except Exception:
                velocities = None
        elif state or pdb:
            positions = np.array(app.PDBFile(state or pdb).getPositions(asNumpy=True).value_in_unit(unit.nanometer))
        else:
            raise InputError("a System XML needs positions: pass a PDB file or a serialized State XML")
        minimize = minimize and velocities is None
    elif pdb:
        if not forcefields:
            raise InputError("a PDB file needs force-field names (e.g. amber14-all.xml amber14/tip3pfb.xml) "
                             "or a serialized System XML")
        pdbfile = app.PDBFile(pdb)
        ff = app.ForceField(*forcefields)
        periodic = pdbfile.topology.getPeriodicBoxVectors() is not None
        system = ff.createSystem(pdbfile.topology, nonbondedMethod=app.PME if periodic else app.NoCutoff,
                                 constraints=app.HBonds, removeCMMotion=False)
        positions = np.array(pdbfile.getPositions(asNumpy=True).value_in_unit(unit.nanometer))
    else:
        raise InputError("a user scene needs --system-xml (with --state or --pdb) or --pdb with --forcefield")
    if system.getNumParticles() != len(positions):
        raise InputError(f"the System has {system.getNumParticles()} particles but the positions have "
                         f"{len(positions)}")
    periodic = system.usesPeriodicBoundaryConditions()
    platform = platform or ("CPU" if periodic else "Reference")
    if minimize:
        positions = minimise(system, positions, platform)
    if velocities is None and periodic:
        # a periodic system is measured like a production run: NVE from an equilibrated state
        positions, velocities = equilibrate(system, positions, temperature, equilibrate_ps, seed, platform=platform)
    elif velocities is None:
        velocities = maxwell_boltzmann(system, positions, temperature, seed)
    if periodic:
        try:
            split_forces(system, slow="reciprocal")  # for the multiple-time-step rows
        except ValueError:
            pass  # no reciprocal space: the MTS rows report an error, the others run
    return Scene(name, system, positions, velocities,
                      f"user system ({system.getNumParticles()} atoms, {system.getNumConstraints()} constraints"
                      f"{', periodic' if periodic else ''})", platform=platform, invariants=_invariants_of(system),
                      temperature=temperature, purpose="production" if periodic else "accuracy",
                      why="Supplied by the user.")
