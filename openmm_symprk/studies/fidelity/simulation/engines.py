"""The fidelity study's rows made into running OpenMM integrators (the rows are data in :mod:`..presets`, what
they are in :mod:`..rowspec`).

:func:`availability` says whether this installation can run a row (the package's thermostat rows need an
integrator that accepts ``temperature=``); :func:`make_integrator` builds a row's integrator; :class:`Engine`
runs one row from a replica state.
"""
from __future__ import annotations

import openmm as mm

from ...core.engine import RowEngine
from ..rowspec import UNAVAILABLE_THERMOSTAT, to_row

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


def Engine(scene, x, v, row, temperature: float, seed: int, threads: int = 1) -> RowEngine:
    """One row running from a replica state (x, v) of ``scene`` (a rigid-water box) on the CPU platform
    (:class:`~...core.engine.RowEngine`).  A leapfrog integrator (OpenMM's Verlet, LangevinMiddle, DPD) starts
    from v(-h/2) (:meth:`~...core.rows.Row.set_state`): the positions of velocity Verlet from the replica state,
    so OpenMM's NVE rows keep the replica's energy."""
    eng = RowEngine(scene, x, v, to_row(row, temperature), seed, threads)
    if eng.row.leapfrog and eng.context is not None:
        import openmm.unit as unit

        v_row = eng.context.getState(getVelocities=True).getVelocities(asNumpy=True).value_in_unit(
            unit.nanometer / unit.picosecond)  # the replica's velocities, carried to the row's masses
        eng.row.set_state(eng.context, x, v_row)
    return eng
