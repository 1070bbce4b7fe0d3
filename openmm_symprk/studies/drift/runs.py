"""One run of a drift study: a row (``{"name", "scene", "row": a Row label, "platform": NAME[:PRECISION]}``) from one
replica state, in :class:`~..core.engine.RowEngine` (a leapfrog row, OpenMM's VerletIntegrator, from v(-h/2)).

The effective energy -- the total energy, plus the heat-bath energy of a thermostat that reports one
(``computeHeatBathEnergy``; zero at the start) -- is sampled every ``sample_ps``; what is stored is the series itself
(t, E), so the drift and its error are computed when the study summarises (:func:`.verdict.run_drift`) and a better
estimator needs no rerun.
"""
from __future__ import annotations

import time

import numpy as np

from ..core.engine import RowEngine
from ..core.rows import Row

__all__ = ["row_of", "run_nve"]


def row_of(row: dict) -> Row:
    """The :class:`~..core.rows.Row` of a drift row."""
    return Row.parse(row["row"])


def run_nve(system, x0, v0, row: dict, cfg: dict, seed: int = 1):
    """(arrays {"t": ps, "e": kJ/mol}, info) of one run (``seed``: a stochastic row's random seed); a blow-up is a
    record (status "blew-up"), not an exception."""
    from ...systems.properties import degrees_of_freedom

    spec = row_of(row)
    eng = RowEngine(spec, system, x0, v0, platform=row["platform"], threads=cfg.get("threads", 1), seed=seed,
                    constraint_tolerance=cfg["constraint_tolerance"])
    info = {"status": "ok", "n_dof": int(degrees_of_freedom(system)), "platform_used": eng.platform}
    n_steps = int(round(float(cfg["length_ps"]) / spec.h_ps))
    every = max(1, int(round(float(cfg["sample_ps"]) / spec.h_ps)))
    ts, es = [], []

    def sample(step):
        s = eng.sample(positions=False, velocities=False)
        # the heat bath's energy is zero at the start (OpenMM 8.6's NoseHooverIntegrator crashes if asked then)
        es.append(s.ke + s.pe + (eng.heat_bath() or 0.0 if step else 0.0))
        ts.append(step * spec.h_ps)

    sample(0)
    done, t0, timed_from = 0, time.perf_counter(), 0
    while done < n_steps:
        if done == every:  # time from the end of the first block: kernel compilation and caches left out
            t0, timed_from = time.perf_counter(), done
        k = min(every, n_steps - done)
        try:
            eng.step(k)
        except Exception as exc:  # a blow-up ends the run; its record says so
            info.update(status="blew-up", failure=f"{type(exc).__name__}: {exc}"[:300])
            break
        done += k
        sample(done)
        if not np.isfinite(es[-1]):
            info.update(status="blew-up", failure="non-finite energy")
            break
    wall = time.perf_counter() - t0
    info.update(steps=done, wall_s=wall, wall_per_ps=wall / max((done - timed_from) * spec.h_ps, 1e-12), E0=es[0])
    return {"t": np.asarray(ts), "e": np.asarray(es)}, info
