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


def make_integrator(row: dict, system: mm.System, temperature: float, seed: int):
    """An OpenMM integrator for ``row`` on ``system`` (already :meth:`~..core.rows.Row.system_for` the row);
    RowUnavailable when this installation lacks an option the row needs (an unknown option of the integrator)."""
    try:
        return to_row(row, temperature).build(system, seed=seed)
    except TypeError as exc:
        if not any(k in str(exc) for k in ("unknown option", "unexpected keyword")):
            raise
        raise RowUnavailable(f"{UNAVAILABLE_THERMOSTAT} ({exc})") from None


def availability(row: dict, scene, temperature: float) -> str | None:
    """None when this installation runs ``row`` on ``scene``; else why not (e.g. UNAVAILABLE_THERMOSTAT ...)."""
    if to_row(row).thermostat == "svr":
        try:
            make_integrator(row, scene.system, temperature, 1)
        except RowUnavailable as exc:
            return str(exc)
    return None


def Engine(scene, x, v, row: dict, temperature: float, seed: int, threads: int = 1) -> RowEngine:
    """One row running from a replica state (x, v) of ``scene`` (a rigid-water box) on the CPU platform
    (:class:`~...core.engine.RowEngine`)."""
    return RowEngine(scene, x, v, to_row(row, temperature), seed, threads)
