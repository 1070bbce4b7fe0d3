"""One run of a drift study: a row (a :class:`~..core.rows.Row` label, platform, precision) from one replica state.

A leapfrog row (OpenMM's VerletIntegrator) starts from v(-h/2) = v0 - (h/2) F(x0)/m, constrained
(:meth:`~..core.rows.Row.set_state`).  The effective energy -- the total energy, plus the heat-bath energy of a
thermostat that reports one (``computeHeatBathEnergy``; zero at the start) -- is sampled every ``sample_ps``; what
is stored is the series itself (t, E), so the drift and its error are computed when the study summarises
(:func:`.verdict.run_drift`) and a better estimator needs no rerun.
"""
from __future__ import annotations

import time

import numpy as np
import openmm as mm
import openmm.unit as unit

from ..core.platforms import properties
from ..core.rows import Row

__all__ = ["row_of", "run_nve"]


def row_of(row: dict) -> Row:
    """The :class:`~..core.rows.Row` of a drift row: its ``row`` label, or (rows stored by earlier versions)
    ``integrator``, ``step_fs`` and ``exact_momentum``."""
    if "row" in row:
        return Row.parse(row["row"])
    return Row(row["integrator"], float(row["step_fs"]), exact_momentum=bool(row.get("exact_momentum", False)))


def run_nve(system, x0, v0, row: dict, cfg: dict, seed: int = 1):
    """(arrays {"t": ps, "e": kJ/mol}, info) of one run (``seed``: a stochastic row's random seed); a blow-up is a
    record (status "blew-up"), not an exception."""
    from ...systems.properties import degrees_of_freedom

    spec = row_of(row)
    ig = spec.build(system, seed=seed, constraint_tolerance=cfg["constraint_tolerance"])
    heat = ig.computeHeatBathEnergy if spec.thermostat and spec.has_heat_bath else None
    plat = mm.Platform.getPlatformByName(row["platform"])
    ctx = mm.Context(system, ig, plat, properties(row["platform"], cfg.get("threads", 1), row.get("precision")))
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
            total = e.getKineticEnergy() + e.getPotentialEnergy()
            if heat is not None and step:  # zero at the start (OpenMM 8.6's NoseHooverIntegrator crashes if asked)
                total += heat()
            es.append(total.value_in_unit(unit.kilojoule_per_mole))

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
