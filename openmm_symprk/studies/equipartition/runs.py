"""One NVE run of the equipartition study: a row (:class:`~..core.rows.Row`, ``rigid:<method>`` included) from a
replica state of the box (:mod:`..core.replicas`), settled for ``settle_ps``, then sampled every ``sample_fs``
(rounded to whole steps): the translational and rotational temperature (3 N - 3 and 3 N degrees of freedom),
potential and total energy.
"""
from __future__ import annotations

import time

import numpy as np

from ...physics.momenta import kinetic_energy
from ...physics.temperature import kinetic_temperatures
from ..core.engine import RowEngine
from ..core.rows import Row

__all__ = ["run_nve"]


def run_nve(box, x, v, label: str, cfg: dict):
    """One NVE run; returns (arrays, info).  arrays: t (ps, from the end of settling), T_trans, T_rot (K),
    pe and etot (kJ/mol).  info: wall_s, steps, force_evals, status ("ok", or "blew up at step S")."""
    row = Row.parse(label)
    every = row.steps_for(cfg["sample_fs"])
    dt_sample = every * row.step_fs * 1e-3
    settle = int(round(cfg["settle_ps"] / dt_sample))
    n_samples = int(round(cfg["length_ps"] / dt_sample)) + 1
    m, molecules, n_constraints = box.masses(), box.molecules, box.system.getNumConstraints()
    t0 = time.perf_counter()
    eng = RowEngine(row, box, x, v, threads=cfg.get("threads", 1))
    out = {k: np.full(n_samples, np.nan) for k in ("t", "T_trans", "T_rot", "pe", "etot")}
    status, steps = "ok", 0
    for i in range(-settle, n_samples):
        if i > -settle:
            eng.step(every)
            steps += every
        if i < 0:
            continue
        xs, vs, pe, _ = eng.sample()
        kt = kinetic_temperatures(xs, vs, m, molecules, True, n_constraints)
        ke = kinetic_energy(vs, m)
        out["t"][i], out["T_trans"][i], out["T_rot"][i] = i * dt_sample, kt.translational, kt.rotational
        out["pe"][i], out["etot"][i] = pe, pe + ke
        if not np.isfinite(pe + ke) or abs(kt.translational) > 1e5:
            status = f"blew up at step {steps}"
            break
    info = {"wall_s": time.perf_counter() - t0, "steps": steps, "force_evals": steps * row.evals_per_step(True),
            "status": status, "sample_ps": dt_sample}
    return out, info
