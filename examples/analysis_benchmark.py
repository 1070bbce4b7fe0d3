"""Speed and memory of the package's water analyses against what MDAnalysis users run for the same numbers.

    python examples/analysis_benchmark.py            (216 SPC/E waters, 1000 frames every 10 fs; ~3 min)
    python examples/analysis_benchmark.py --quick    (64 waters, 100 frames: seconds, for the test-suite)

A plain OpenMM simulation (VerletIntegrator, OpenMM's DCDReporter) writes the trajectory; it is loaded into
memory once (``Universe.transfer_to_memory``), and every analysis below runs on that same in-memory Universe,
so reading the file is no one's cost.  Each is timed (best of ``--repeat`` runs, wall clock) and its peak
memory measured separately with tracemalloc (numpy's allocations included):

* reorientation: :class:`openmm_symprk.analysis.universe.Reorientation` (C_2 of dipole, H-H, O-H, every time
  origin, FFT, with tau_2 and its jackknife error) against the ``waterdynamics`` MDAKit's
  ``WaterOrientationalRelaxation`` (C_2 of the same three vectors, lags 1..``--lags`` frames, origins spaced by
  the lag);
* diffusion: :class:`~openmm_symprk.analysis.universe.SelfDiffusion` (molecules made whole, centres of mass,
  unwrapped, FFT MSD, fit and error) against MDAnalysis' ``EinsteinMSD`` (FFT, tidynamics) on the oxygens
  unwrapped by MDAnalysis' ``NoJump`` transformation (what its documentation prescribes; per atom, not per
  centre of mass), and against the centre-of-mass route an MDAnalysis user writes (``center_of_mass(
  compound="residues")`` per frame, then ``EinsteinMSD``);
* g(r): MDAnalysis' ``InterRDF`` of the oxygens (what the package uses) against a numpy all-pairs histogram
  (the package's former implementation), to state the margin that decided it.

Prints one table: seconds, peak MiB, and each peer's time and memory as a ratio to the package's.
"""
import argparse
import os
import tempfile
import time
import tracemalloc
import warnings

import numpy as np

warnings.filterwarnings("ignore")

parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
parser.add_argument("--quick", action="store_true", help="64 waters, 100 frames (seconds)")
parser.add_argument("--waters", type=int, default=None, help="default 216 (64 with --quick)")
parser.add_argument("--frames", type=int, default=None, help="default 1000 (100 with --quick)")
parser.add_argument("--lags", type=int, default=None, help="waterdynamics' dtmax, frames (default 10; 2 with --quick)")
parser.add_argument("--repeat", type=int, default=None,
                    help="timed runs of each, best kept (default 3; 1 with --quick)")
parser.add_argument("--out", default=None, help="folder for the trajectory (default: a temporary folder)")
args = parser.parse_args()
n_waters = args.waters or (64 if args.quick else 216)
n_frames = args.frames or (100 if args.quick else 1000)
lags = args.lags or (2 if args.quick else 10)
repeat = args.repeat or (1 if args.quick else 3)

import MDAnalysis as mda  # noqa: E402
import openmm as mm  # noqa: E402
import openmm.app as app  # noqa: E402
import openmm.unit as unit  # noqa: E402
from MDAnalysis.analysis.msd import EinsteinMSD  # noqa: E402
from MDAnalysis.coordinates.memory import MemoryReader  # noqa: E402
from MDAnalysis.transformations.nojump import NoJump  # noqa: E402
from waterdynamics import WaterOrientationalRelaxation  # noqa: E402

from openmm_symprk.analysis.universe import RadialDistribution, Reorientation, SelfDiffusion  # noqa: E402
from openmm_symprk.systems.prepare import equilibrate, minimise  # noqa: E402
from openmm_symprk.systems.scenes import water_box  # noqa: E402


def write_trajectory(folder):
    """216 (or n) SPC/E waters, 2 ps of Langevin equilibration, then n_frames frames every 10 fs of plain
    OpenMM Verlet dynamics written by OpenMM's DCDReporter."""
    pdb, dcd = os.path.join(folder, f"water{n_waters}.pdb"), os.path.join(folder, f"water{n_waters}_{n_frames}.dcd")
    if os.path.exists(pdb) and os.path.exists(dcd):
        return pdb, dcd
    system, topology, positions = water_box("spce", n_waters=n_waters, cutoff_nm=0.55 if n_waters < 150 else 0.9)
    x, v = equilibrate(system, minimise(system, positions, max_iterations=100), 300.0, 2.0, seed=7)
    sim = app.Simulation(topology, system, mm.VerletIntegrator(2 * unit.femtoseconds),
                         mm.Platform.getPlatformByName("CPU"))
    sim.context.setPositions(x)
    sim.context.setVelocities(v)
    with open(pdb, "w") as fh:
        app.PDBFile.writeFile(topology, x * unit.nanometer, fh)
    reporter = app.DCDReporter(dcd, 5)
    sim.reporters.append(reporter)
    sim.step(5 * n_frames)
    sim.reporters.clear()
    del reporter, sim  # closes the DCD
    return pdb, dcd


def measure(fn, setup=lambda: None):
    """(best wall time of ``repeat`` runs of ``fn(setup())``, s, the setup untimed (one run only when it takes
    over 20 s); peak memory traced during one more run, MiB; its result)."""
    best = float("inf")
    for _ in range(repeat):
        arg = setup()
        t0 = time.perf_counter()
        fn(arg)
        best = min(best, time.perf_counter() - t0)
        if best > 20.0:
            break
    arg = setup()
    tracemalloc.start()
    result = fn(arg)
    peak = tracemalloc.get_traced_memory()[1] / 2 ** 20
    tracemalloc.stop()
    return best, peak, result


def universe(pdb, dcd):
    u = mda.Universe(pdb, dcd)
    u.transfer_to_memory()
    return u


def ours_reorientation(u):
    return Reorientation(u, orders=(2,), max_lag=lags).run().results


def waterdynamics_reorientation(u):
    w = WaterOrientationalRelaxation(u, "byres name O", 0, u.trajectory.n_frames, lags, order=2)
    w.run()
    return w.timeseries


def ours_diffusion(u):
    return SelfDiffusion(u).run().results


def einstein_msd_nojump(u):
    """EinsteinMSD of the oxygens made continuous by NoJump (added to a fresh copy of the Universe, untimed)."""
    u.trajectory.add_transformations(NoJump())
    return EinsteinMSD(u, select="name O", msd_type="xyz", fft=True).run().results.timeseries


def einstein_msd_com(u):
    """The centre-of-mass route: each residue's centre of mass per frame (molecules whole in this DCD: OpenMM
    wraps whole molecules), unwrapped by NoJump, then EinsteinMSD."""
    water = u.select_atoms("resname HOH")
    com = np.array([water.center_of_mass(compound="residues") for _ in u.trajectory])
    c = mda.Universe.empty(com.shape[1], trajectory=False)
    c.load_new(com, format=MemoryReader, dimensions=u.dimensions)
    c.trajectory.add_transformations(NoJump())
    return EinsteinMSD(c, msd_type="xyz", fft=True).run().results.timeseries


def ours_rdf(u):
    return RadialDistribution(u).run().results


def numpy_rdf(u):
    """g(r) of the oxygens by a numpy all-pairs histogram with the minimum image (no neighbour grid)."""
    o = u.select_atoms("name O")
    box = u.dimensions[:3]
    edges = np.arange(0.0, 0.5 * box.min() + 1e-9, 0.05)
    i, j = np.triu_indices(o.n_atoms, k=1)
    counts = np.zeros(len(edges) - 1)
    for _ in u.trajectory:
        d = o.positions[j] - o.positions[i]
        d -= box * np.round(d / box)
        counts += np.histogram(np.sqrt((d * d).sum(axis=1)), bins=edges)[0]
    shell = 4.0 * np.pi * (edges[1:] ** 3 - edges[:-1] ** 3) / 3.0
    return counts * np.prod(box) / (u.trajectory.n_frames * 0.5 * o.n_atoms * (o.n_atoms - 1) * shell)


folder = args.out or tempfile.mkdtemp(prefix="symprk-bench-")
os.makedirs(folder, exist_ok=True)
pdb, dcd = write_trajectory(folder)
u = universe(pdb, dcd)
print(f"{u.residues.n_residues} waters, {u.trajectory.n_frames} frames every {u.trajectory.dt:g} ps "
      f"({dcd}); best of {repeat}, peak memory by tracemalloc", flush=True)
HEADER = (f"{'analysis':38s} {'peer':50s} {'ours s':>8s} {'MiB':>7s} {'peer s':>8s} {'MiB':>7s} "
          f"{'speed':>7s} {'memory':>7s}")
print("\n" + HEADER, flush=True)


def row(what, peer, ot, om, pt, pm, note):
    """One line of the table, printed as soon as it is measured."""
    print(f"{what:38s} {peer:50s} {ot:8.3f} {om:7.1f} {pt:8.3f} {pm:7.1f} {pt / ot:6.1f}x {pm / om:6.2f}x  {note}",
          flush=True)


same = lambda: u  # noqa: E731 - every analysis reads the same in-memory Universe
ours_t, ours_m, res = measure(ours_reorientation, same)
peer_t, peer_m, ref = measure(waterdynamics_reorientation, same)
agree = np.abs(res.C["HH"]["C2"][1:lags + 1] - np.array([r[1] for r in ref])).max()
row("reorientation C2 (dipole, H-H, O-H)", "waterdynamics WaterOrientationalRelaxation", ours_t, ours_m, peer_t,
    peer_m, f"|dC2(H-H)| <= {agree:.3f}")
ours_t, ours_m, res = measure(ours_diffusion, same)
peer_t, peer_m, ref = measure(einstein_msd_nojump, u.copy)
row("diffusion (COM MSD, fit, error)", "EinsteinMSD on O + NoJump (per atom)", ours_t, ours_m, peer_t, peer_m,
    f"D = {res.D:.2f} ± {res.se:.2f}")
peer_t, peer_m, ref = measure(einstein_msd_com, same)
ours_nodrift = SelfDiffusion(u, drift=False).run().results.timeseries  # Angstrom^2, as EinsteinMSD's
gap = np.abs(ref[:len(ours_nodrift)] - ours_nodrift).max()
row("", "center_of_mass per frame + NoJump + EinsteinMSD", ours_t, ours_m, peer_t, peer_m,
    f"|dMSD| <= {gap:.1e} A2 (drift left in)")
ours_t, ours_m, res = measure(ours_rdf, same)
peer_t, peer_m, ref = measure(numpy_rdf, same)
row("g(r) O-O: InterRDF (used)", "numpy all-pairs histogram", ours_t, ours_m, peer_t, peer_m,
    f"peak {res.peak.r:.2f} A" if res.peak is not None else "-")
print("\nspeed: the peer's time / ours (above 1: ours is faster); memory: the peer's peak / ours")
