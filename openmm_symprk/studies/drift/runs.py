"""One NVE run of a drift study: a row (integrator, step, platform, precision, exact_momentum) from one replica state.

Rows: ``integrator`` is ``"openmm-verlet"`` (OpenMM's VerletIntegrator, leapfrog: it starts from
v(-h/2) = v0 - (h/2) F(x0)/m, constrained, the bench's convention) or a catalogue method run by
:class:`~openmm_symprk.SymplecticIntegrator` (native backend where available), with ``exact_momentum``.  The total
energy is sampled every ``sample_ps``; what is stored is the series itself (t, E), so the drift and its error are
computed when the study summarises (:func:`.verdict.run_drift`) and a better estimator needs no rerun.
"""
from __future__ import annotations

import time

import numpy as np
import openmm as mm
import openmm.unit as unit

from ..core.rows import Row

__all__ = ["row_of", "properties", "run_nve"]


def row_of(row: dict) -> Row:
    """The :class:`~..core.rows.Row` of a drift row (``integrator``, ``step_fs``, ``exact_momentum``)."""
    return Row(row["integrator"], float(row["step_fs"]), exact_momentum=bool(row.get("exact_momentum", False)))


def properties(row: dict, threads: int) -> dict:
    if row["platform"] == "CPU":
        return {"Threads": str(int(threads))}
    if row.get("precision"):
        return {"Precision": row["precision"]}
    return {}


def run_nve(system, x0, v0, row: dict, cfg: dict):
    """(arrays {"t": ps, "e": kJ/mol}, info) of one NVE run; a blow-up is a record (status "blew-up"), not an
    exception."""
    from ...systems.properties import degrees_of_freedom

    spec = row_of(row)
    ig = spec.build(system, constraint_tolerance=cfg["constraint_tolerance"])
    plat = mm.Platform.getPlatformByName(row["platform"])
    ctx = mm.Context(system, ig, plat, properties(row, cfg.get("threads", 1)))
    info = {"status": "ok", "n_dof": int(degrees_of_freedom(system)), "platform_used": plat.getName()}
    try:
        spec.set_state(ctx, x0, v0)
        h_ps = float(row["step_fs"]) * 1e-3
        n_steps = int(round(float(cfg["length_ps"]) / h_ps))
        every = max(1, int(round(float(cfg["sample_ps"]) / h_ps)))
        ts, es = [], []

        def sample(step):
            e = ctx.getState(getEnergy=True)
            ts.append(step * h_ps)
            es.append((e.getKineticEnergy() + e.getPotentialEnergy()).value_in_unit(unit.kilojoule_per_mole))

        sample(0)
        done, t0, timed_from = 0, time.perf_counter(), 0
        while done < n_steps:
            if done == every:  # time from the end of the first block: kernel compilation and caches left out
                t0, timed_from = time.perf_counter(), done
            k = min(every, n_steps - done)
            try:
                ig.step(k)
            except Exception as exc:  # a blow-up ends the run; its record says so
                info.update(status="blew-up", failure=f"{type(exc).__name__}: {exc}"[:300])
                break
            done += k
            sample(done)
            if not np.isfinite(es[-1]):
                info.update(status="blew-up", failure="non-finite energy")
                break
        wall = time.perf_counter() - t0
        info.update(steps=done, wall_s=wall, wall_per_ps=wall / max((done - timed_from) * h_ps, 1e-12), E0=es[0])
        return {"t": np.asarray(ts), "e": np.asarray(es)}, info
    finally:
        ctx = None  # the Context goes before the caller's next one (the closure above holds the name)
