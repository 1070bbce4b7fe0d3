"""Reporters for ``openmm.app.Simulation``: conservation figures and velocity-carrying trajectories.

    from openmm_symprk.conservation import ConservationReporter, VelocityTRRReporter
    simulation.reporters.append(ConservationReporter("conservation.csv", 100))
    simulation.reporters.append(VelocityTRRReporter("traj.trr", 100))

Both use the dict form of ``describeNextReport`` that OpenMM 8 Simulation expects
(``{'steps', 'periodic', 'include'}``; Simulation 8.6 still converts the old tuple form).  Positions
are requested unwrapped (``periodic: False``): wrapping molecules into a box would change the angular
momentum that is being reported.

:class:`ConservationReporter` writes, like ``StateDataReporter``, one line per report: step, time,
total energy (plus the heat-bath energy for an integrator of this package run with ``temperature=``: the
conserved effective energy of NVT, and the column says so), its drift (slope of a least-squares line through all reports so far, in kJ/mol per ns
per degree of freedom; :class:`openmm_symprk.stats.RunningLine`, constant work per report), |P - P0|, |L - L0|/|L0| (L about the centre of mass, or about the origin),
the largest relative constraint violation, the translational and rotational kinetic temperatures of the
molecules (:mod:`openmm_symprk.physics.temperature`), and with the package's thermostat the temperature at the
thermostat point (``T at the thermostat``: the velocities just after its last event, which with
``thermostat_position="middle"`` are not the State's on-step ones); every figure is computed in float64 from the State
(:mod:`openmm_symprk.physics`).  At its first report it warns once, with the reason, about
anything that keeps the system from conserving what is reported (:mod:`openmm_symprk.systems.checks`:
the System's issues and thermostatting integrators, one :class:`~openmm_symprk.systems.checks.ConservationWarning` per kind).

:class:`VelocityTRRReporter` writes positions (nm), velocities (nm/ps), step and time to a GROMACS TRR
file with MDAnalysis' XDR library (no extra dependency); MDAnalysis reads it back with velocities.
TRR stores float32: figures recomputed from the file are limited to ~1e-7 relative
(:mod:`openmm_symprk.conservation.analysis`).  Virtual sites, which OpenMM reports with zero velocity, are
written with their true velocity, computed from their parents' (:mod:`openmm_symprk.systems.virtual_sites`).  Each frame is complete on disk when ``report()`` returns, so
the file can be read while the simulation runs.  :func:`write_topology` writes the matching PDB.
"""
from __future__ import annotations

import numbers
import os
import sys

import numpy as np
import openmm.app as app
import openmm.unit as unit

from ..physics import momenta
from ..physics.temperature import kinetic_temperatures
from ..support import InputError, require
from ..stats.slope import RunningLine
from ..systems.checks import conservation_issues, integrator_issues, warn_conservation, warn_once
from ..systems.properties import constraint_arrays, constraint_violation, degrees_of_freedom, masses, molecules
from ..systems.virtual_sites import VirtualSiteVelocities

_NM, _NM_PS, _KJ = unit.nanometer, unit.nanometer / unit.picosecond, unit.kilojoule_per_mole


def report_interval(value) -> int:
    """``value`` as a number of steps: a positive integer (a float such as 2.5, or True, is refused, not truncated)."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral) or int(value) < 1:
        raise InputError(f"reportInterval must be a positive whole number of steps (an int such as 100), "
                         f"got {value!r}")
    return int(value)


def _open(file, append):
    if file is None or file == "-":
        return sys.stdout, False
    if isinstance(file, str):
        return open(file, "a" if append else "w"), True
    return file, False


class ConservationReporter:
    """Report energy, momentum and constraint conservation of a Simulation.

    Parameters
    ----------
    file : str, file object or None
        A file name, an open file, or None / "-" for stdout.
    reportInterval : int
        Steps between reports.
    about : "com" or "origin"
        Point about which L is measured (both are conserved in an isolated system; a CMMotionRemover
        keeps L about the centre of mass but not about the origin).
    separator : str
    append : bool
        Append to an existing file (no header).
    warn : bool
        Warn once, with the reason, if the system cannot conserve the reported quantities.

    ``records`` holds every report as a dict of floats (float64), for programmatic checks.
    """

    COLUMNS = ("Step", "Time (ps)", "Total Energy (kJ/mol)", "Energy drift (kJ/mol/ns/dof)",
               "|dP| (amu nm/ps)", "|dL|/|L|", "Constraint error", "T_trans (K)", "T_rot (K)")

    def __init__(self, file, reportInterval: int, about: str = "com", separator: str = ",",
                 append: bool = False, warn: bool = True):
        self._interval = report_interval(reportInterval)
        if about not in ("com", "origin"):
            raise InputError(f"about must be 'com' or 'origin', got {about!r}")
        self._about = about
        self._sep = separator
        self._append = append
        self._warn = warn
        self._out, self._owns = _open(file, append)
        self._initialised = False
        self.records: list = []
        self.issues: list = []

    # -- the Simulation reporter protocol ------------------------------------------------------
    def describeNextReport(self, simulation):
        steps = self._interval - simulation.currentStep % self._interval
        return {"steps": steps, "periodic": False, "include": ["positions", "velocities", "energy"]}

    def report(self, simulation, state):
        if not self._initialised:
            self._initialise(simulation)
        x = state.getPositions(asNumpy=True).value_in_unit(_NM)
        v = state.getVelocities(asNumpy=True).value_in_unit(_NM_PS)
        x, v = np.asarray(x, dtype=np.float64), np.asarray(v, dtype=np.float64)
        m = self._masses
        P = momenta.linear_momentum(v, m)
        L = momenta.angular_momentum(x, v, m, about=self._about)
        ke = momenta.kinetic_energy(v, m)
        total = ke + state.getPotentialEnergy().value_in_unit(_KJ)
        heat_bath = self._heat_bath(simulation)
        total += heat_bath  # NVT with the package's thermostat: the conserved effective energy
        t = state.getTime().value_in_unit(unit.picosecond)
        step = simulation.currentStep
        if self._P0 is None:
            self._P0, self._L0 = P, L
        slope = self._line.add(t, total).slope  # NaN until two reports at different times
        drift = slope * 1000.0 / max(self._dof, 1)  # per ps -> per ns
        nL0 = float(np.linalg.norm(self._L0))
        temps = kinetic_temperatures(x, v, m, self._molecules, True, self._system.getNumConstraints())
        rec = {"step": step, "time": t, "total_energy": total, "heat_bath": heat_bath, "energy_drift": drift,
               "dP": float(np.linalg.norm(P - self._P0)),
               "dL_rel": float(np.linalg.norm(L - self._L0) / nL0) if nL0 > 0 else float("nan"),
               "constraint_error": constraint_violation(x, self._constraints),
               "T_trans": temps.translational, "T_rot": temps.rotational}
        vals = [str(step), f"{t:.6g}", f"{total:.10g}", f"{drift:.4g}", f"{rec['dP']:.4g}",
                f"{rec['dL_rel']:.4g}", f"{rec['constraint_error']:.4g}", f"{rec['T_trans']:.5g}",
                f"{rec['T_rot']:.5g}"]
        if self._thermostat is not None:
            # the temperature the thermostat samples (its last event's peculiar kinetic energy over its degrees of freedom)
            rec["T_thermostat"] = float(simulation.integrator.computeSystemTemperature().value_in_unit(unit.kelvin))
            vals.append(f"{rec['T_thermostat']:.5g}")
        self.records.append(rec)
        print(self._sep.join(vals), file=self._out)
        try:
            self._out.flush()
        except AttributeError:
            pass

    # -- helpers ----------------------------------------------------------------------------------
    @staticmethod
    def _heat_bath(simulation) -> float:
        """The heat-bath energy (kJ/mol) of an integrator of this package run with ``temperature=``, else 0."""
        integrator = simulation.integrator
        if getattr(integrator, "thermostat", None) is None:
            return 0.0
        return float(integrator.computeHeatBathEnergy().value_in_unit(_KJ))

    def _initialise(self, simulation):
        self._system = simulation.system
        self._masses = masses(self._system)
        self._constraints = constraint_arrays(self._system)
        self._molecules = [list(g) for g in molecules(simulation.context)]
        self._dof = degrees_of_freedom(self._system)
        self._P0 = self._L0 = None
        self._line = RunningLine()
        self.issues = conservation_issues(self._system) + integrator_issues(simulation.integrator)
        if self._warn:
            warn_conservation(self._system, context="ConservationReporter")
            for key, msg in integrator_issues(simulation.integrator):
                warn_once(key, f"ConservationReporter: {msg}")
        self._thermostat = getattr(simulation.integrator, "thermostat", None)
        if self._thermostat is not None and not hasattr(simulation.integrator, "thermostat_kinetic_energy"):
            self._thermostat = None
        if not self._append:
            columns = list(self.COLUMNS)
            if self._thermostat is not None:
                columns[2] = "Total + heat-bath energy (kJ/mol)"
                columns.append("T at the thermostat (K)")
            print("#" + self._sep.join(f'"{c}"' for c in columns), file=self._out)
        self._initialised = True

    def close(self):
        if self._owns:
            self._out.close()

    def __del__(self):
        try:
            self.close()
        except Exception:
            pass



class VelocityTRRReporter:
    """Write positions, velocities, step and time to a GROMACS TRR file (float32, nm and nm/ps).

    Every frame is on disk, complete and readable, when ``report()`` returns: a TRR file is a sequence of
    self-contained frames, so each report is encoded by MDAnalysis' XDR library into a one-frame buffer and
    appended to the trajectory with a flush.  Another process (a notebook, a monitor) can read the file while
    the simulation runs; ``append=True`` (a restart) adds frames after the existing ones without rewriting
    them.  MDAnalysis reads it with velocities: ``mda.Universe("top.pdb", "traj.trr")`` (MDAnalysis converts
    to Angstrom and Angstrom/ps), or :func:`openmm_symprk.conservation.analysis.universe`.  Virtual sites are
    written with the velocity they move with (OpenMM's State gives them zero), computed from their parents'
    velocities for every OpenMM virtual-site type; a type it does not know keeps zero, with one warning."""

    def __init__(self, file: str, reportInterval: int, append: bool = False, forces: bool = False):
        import tempfile

        # fail here, not at the first report
        require("MDAnalysis.lib.formats.libmdaxdr", "analysis", "openmm_symprk.conservation.VelocityTRRReporter")

        self._interval = report_interval(reportInterval)
        self._forces = forces
        self._sites = None
        self.path = str(file)
        self.frames = self._count_frames() if append else 0
        with open(self.path, "ab" if append else "wb"):
            pass  # create (or keep) the file now: a bad path fails here, not after the first segment
        fd, self._buffer = tempfile.mkstemp(suffix=".trr", prefix="symprk-frame-")
        os.close(fd)

    def _count_frames(self) -> int:
        TRRFile = require("MDAnalysis.lib.formats.libmdaxdr", "analysis",
                          "openmm_symprk.conservation.VelocityTRRReporter").TRRFile

        if not os.path.exists(self.path) or os.path.getsize(self.path) == 0:
            return 0
        with TRRFile(self.path, "r") as f:
            return len(f.offsets)

    def describeNextReport(self, simulation):
        steps = self._interval - simulation.currentStep % self._interval
        include = ["positions", "velocities"] + (["forces"] if self._forces else [])
        return {"steps": steps, "periodic": False, "include": include}

    def report(self, simulation, state):
        TRRFile = require("MDAnalysis.lib.formats.libmdaxdr", "analysis",
                          "openmm_symprk.conservation.VelocityTRRReporter").TRRFile

        if self._sites is None:
            self._sites = VirtualSiteVelocities(simulation.system)
            for i, kind in self._sites.unsupported[:1]:
                warn_once(f"virtual-site-{kind}", f"VelocityTRRReporter: virtual sites of type {kind} (particle {i}"
                          f"{' and others' if len(self._sites.unsupported) > 1 else ''}) are written with OpenMM's "
                          f"zero velocity: their velocity from the parents' is not known for that type",
                          category=UserWarning)
        x = np.asarray(state.getPositions(asNumpy=True).value_in_unit(_NM), dtype=np.float64)
        v = np.asarray(state.getVelocities(asNumpy=True).value_in_unit(_NM_PS), dtype=np.float64)
        if self._sites:
            v = self._sites(x, v)
        x, v = x.astype(np.float32), v.astype(np.float32)
        f = None
        if self._forces:
            f = np.asarray(state.getForces(asNumpy=True).value_in_unit(_KJ / _NM), dtype=np.float32)
        box = np.zeros((3, 3), dtype=np.float32)
        if simulation.system.usesPeriodicBoundaryConditions():
            box = np.asarray(state.getPeriodicBoxVectors(asNumpy=True).value_in_unit(_NM), dtype=np.float32)
        with TRRFile(self._buffer, "w") as frame:
            frame.write(x, v, f, box, int(simulation.currentStep), float(state.getTime().value_in_unit(unit.picosecond)),
                        0.0, len(x))
        with open(self._buffer, "rb") as src:
            data = src.read()
        with open(self.path, "ab") as out:
            out.write(data)
            out.flush()
            os.fsync(out.fileno())
        self.frames += 1

    def close(self):
        """Remove the one-frame buffer (the trajectory itself is always complete)."""
        if getattr(self, "_buffer", None) and os.path.exists(self._buffer):
            os.remove(self._buffer)
        self._buffer = None

    def __del__(self):
        try:
            self.close()
        except Exception:
            pass


def write_topology(path: str, topology: app.Topology, positions) -> None:
    """Write the PDB file that MDAnalysis pairs with a trajectory (``positions`` in nm or a Quantity)."""
    if not unit.is_quantity(positions):
        positions = np.asarray(positions) * unit.nanometer
    with open(path, "w", encoding="utf-8") as fh:
        app.PDBFile.writeFile(topology, positions, fh, keepIds=True)
