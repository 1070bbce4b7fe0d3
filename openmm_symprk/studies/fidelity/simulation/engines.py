"""The fidelity study's rows made into running OpenMM integrators (the rows are data in :mod:`..presets`, what
they are in :mod:`..rowspec`).

:func:`availability` says whether this installation can run a row (the package's thermostat rows need an
integrator that accepts ``temperature=``); :func:`make_integrator` builds a row's integrator; :class:`Engine`
runs one row from a replica state.
"""
from __future__ import annotations

import numpy as np
import openmm as mm
import openmm.unit as unit

from ....systems.properties import masses
from ....systems.repartition import repartition_hydrogen_mass, rigid_velocities_for_masses
from ..rowspec import UNAVAILABLE_THERMOSTAT, describe

__all__ = ["RowUnavailable", "availability", "make_integrator", "Engine"]


class RowUnavailable(RuntimeError):
    """This installation cannot run the row (e.g. the integrator does not accept ``temperature=``)."""


def _thermostatted(row, system, temperature, seed):
    """The package's thermostatted integrator, or RowUnavailable when the integrator has no thermostat yet."""
    from ....integrators import SymplecticIntegrator

    try:
        return SymplecticIntegrator(row["step_fs"] * unit.femtoseconds, row["method"], system=system,
                                    temperature=temperature * unit.kelvin,
                                    collision_time=row["collision_time_ps"] * unit.picoseconds, random_seed=seed)
    except TypeError as exc:  # an unexpected keyword: the thermostat is not in this installation
        raise RowUnavailable(f"{UNAVAILABLE_THERMOSTAT} ({exc})") from None
    except ValueError as exc:
        if any(k in str(exc) for k in ("temperature", "collision_time", "random_seed")):
            raise RowUnavailable(f"{UNAVAILABLE_THERMOSTAT} ({exc})") from None
        raise


def make_integrator(row: dict, system: mm.System, temperature: float, seed: int, cutoff_nm: float):
    """An OpenMM integrator for ``row`` on ``system`` (already repartitioned / split in force groups)."""
    kind, h = row["kind"], row["step_fs"] * unit.femtoseconds
    T = temperature * unit.kelvin
    if kind == "symprk":
        if "collision_time_ps" in row:
            return _thermostatted(row, system, temperature, seed)
        from ....integrators import SymplecticIntegrator

        return SymplecticIntegrator(h, row["method"], system=system)
    if kind == "langevin":
        integ = mm.LangevinMiddleIntegrator(T, row["friction_per_ps"] / unit.picosecond, h)
    elif kind == "mts-langevin":
        integ = mm.MTSLangevinIntegrator(T, row["friction_per_ps"] / unit.picosecond, h,
                                         [(1, 1), (0, int(row["inner_steps"]))])
    elif kind == "nose-hoover":
        return mm.NoseHooverIntegrator(T, row["collision_frequency_per_ps"] / unit.picosecond, h)
    else:
        integ = mm.DPDIntegrator(T, row["friction_per_ps"] / unit.picosecond,
                                 row.get("cutoff_nm", cutoff_nm) * unit.nanometer, h)
    integ.setRandomNumberSeed(seed)
    return integ


def _system_for(row, scene):
    """The row's System: HMR repartitioned, and for MTS reciprocal-space PME in force group 1."""
    system = scene.system
    if "hmr_da" in row:
        system = repartition_hydrogen_mass(system, scene.topology, row["hmr_da"])
    if row["kind"] == "mts-langevin":
        if system is scene.system:
            system = mm.XmlSerializer.deserialize(mm.XmlSerializer.serialize(system))
        for f in system.getForces():
            if isinstance(f, mm.NonbondedForce):
                f.setReciprocalSpaceForceGroup(1)
    return system


def availability(row: dict, scene, temperature: float) -> str | None:
    """None when this installation runs ``row`` on ``scene``; else why not (e.g. UNAVAILABLE_THERMOSTAT ...)."""
    if row["kind"] == "symprk" and "collision_time_ps" in row:
        try:
            _thermostatted(row, scene.system, temperature, 1)
        except RowUnavailable as exc:
            return str(exc)
    return None


def _nonbonded_cutoff(system) -> float:
    for f in system.getForces():
        if isinstance(f, mm.NonbondedForce):
            return f.getCutoffDistance().value_in_unit(unit.nanometer)
    return 1.0


class Engine:
    """One row running from a replica state (x, v) of ``scene`` (a rigid-water box) on the CPU platform.
    ``masses``: the row's masses (HMR changes them; the velocities are carried over by
    :func:`~openmm_symprk.systems.repartition.rigid_velocities_for_masses`)."""

    def __init__(self, scene, x, v, row: dict, temperature: float, seed: int, threads: int = 1):
        self.row, self.info = row, describe(row)
        self.system = _system_for(row, scene)
        self.masses = masses(self.system)
        if "hmr_da" in row:
            v = rigid_velocities_for_masses(x, v, scene.masses(), self.masses, scene.molecules)
        self.integrator = make_integrator(row, self.system, temperature, seed, _nonbonded_cutoff(self.system))
        self.context = mm.Context(self.system, self.integrator, mm.Platform.getPlatformByName("CPU"),
                                  {"Threads": str(threads)})
        self.context.setPositions(x)
        self.context.setVelocities(v)

    def step(self, n: int):
        self.integrator.step(int(n))

    def heat_bath(self) -> float | None:
        """The heat bath's energy (kJ/mol) of an integrator that exposes one, 0 for NVE, None otherwise."""
        if self.info["ensemble"] == "NVE":
            return 0.0
        fn = getattr(self.integrator, "computeHeatBathEnergy", None)
        if fn is None or not self.info["effective_energy"]:
            return None
        e = fn()
        return float(e.value_in_unit(unit.kilojoule_per_mole) if unit.is_quantity(e) else e)

    def sample(self, velocities: bool = True, energy: bool = True):
        """(x nm, v nm/ps or None, potential energy kJ/mol or None) now."""
        st = self.context.getState(getPositions=True, getVelocities=velocities, getEnergy=energy)
        x = np.asarray(st.getPositions(asNumpy=True).value_in_unit(unit.nanometer))
        v = np.asarray(st.getVelocities(asNumpy=True).value_in_unit(unit.nanometer / unit.picosecond)) \
            if velocities else None
        pe = st.getPotentialEnergy().value_in_unit(unit.kilojoule_per_mole) if energy else None
        return x, v, pe
