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
from ....systems.repartition import rigid_velocities_for_masses
from ..rowspec import UNAVAILABLE_THERMOSTAT, describe, to_row

__all__ = ["RowUnavailable", "availability", "make_integrator", "Engine"]


class RowUnavailable(RuntimeError):
    """This installation cannot run the row (e.g. the integrator does not accept ``temperature=``)."""


def make_integrator(row, system: mm.System, temperature: float, seed: int):
    """An OpenMM integrator for ``row`` on ``system`` (already :meth:`~..core.rows.Row.system_for` the row);
    RowUnavailable when this installation lacks an option the row needs (an unknown option of the integrator)."""
    try:
        return to_row(row, temperature).build(system, seed=seed)
    except TypeError as exc:
        if not any(k in str(exc) for k in ("unknown option", "unexpected keyword")):
            raise
        raise RowUnavailable(f"{UNAVAILABLE_THERMOSTAT} ({exc})") from None


def availability(row, scene, temperature: float) -> str | None:
    """None when this installation runs ``row`` on ``scene``; else why not (e.g. UNAVAILABLE_THERMOSTAT ...)."""
    r = to_row(row)
    if r.thermostat == "svr":
        system = r.system_for(scene.system, scene.topology) if r.mts or r.hmr_da is not None else scene.system
        try:
            make_integrator(row, system, temperature, 1)
        except RowUnavailable as exc:
            return str(exc)
    return None


class Engine:
    """One row running from a replica state (x, v) of ``scene`` (a rigid-water box) on the CPU platform.
    ``masses``: the row's masses (HMR changes them; the velocities are carried over by
    :func:`~openmm_symprk.systems.repartition.rigid_velocities_for_masses`)."""

    def __init__(self, scene, x, v, row, temperature: float, seed: int, threads: int = 1):
        self.row, self.info = to_row(row, temperature), describe(row)
        self.system = self.row.system_for(scene.system, scene.topology)
        self.masses = masses(self.system)
        if self.row.hmr_da is not None:
            v = rigid_velocities_for_masses(x, v, scene.masses(), self.masses, scene.molecules)
        self.integrator = make_integrator(row, self.system, temperature, seed)
        self.context = mm.Context(self.system, self.integrator, mm.Platform.getPlatformByName("CPU"),
                                  {"Threads": str(threads)})
        # a leapfrog integrator (OpenMM's Verlet, LangevinMiddle, DPD) starts from v(-h/2): the positions of
        # velocity Verlet from the replica state (x, v), so NVE rows of OpenMM keep the replica's energy
        self.row.set_state(self.context, x, v)

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
