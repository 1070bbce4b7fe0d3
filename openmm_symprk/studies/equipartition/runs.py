"""The OpenMM side of the equipartition study: the water box, its replica states and one NVE run.

A run starts from a replica state (positions and on-step, constrained velocities after Langevin dynamics),
lets the method settle for ``settle_ps`` (the kinetic energy redistributes itself in the method's own
dynamics within a picosecond), then records every ``sample_fs``: time, translational and rotational
temperature (3 N - 3 and 3 N degrees of freedom), potential and total energy.
"""
from __future__ import annotations

import time

import numpy as np

from ...physics.momenta import kinetic_energy
from ...physics.temperature import kinetic_temperatures
from ...systems.prepare import equilibrate, minimise, without_net_momentum
from ...systems.scenes import WATER_DENSITY_G_CM3, Scene, water_box
from ..core.engine import RowEngine
from ..core.rows import Row

__all__ = ["build_box", "replica_states", "run_nve", "steps_per_sample", "force_evals_per_step", "make_engine"]


def build_box(cfg: dict, model: str) -> Scene:
    """The study's water box for one model (:func:`openmm_symprk.systems.scenes.water_box`) as a Scene whose
    ``meta["model"]`` names the model; its state is Modeller's (see :func:`replica_states`)."""
    system, topology, x = water_box(model, cfg["n_waters"], cfg["cutoff_nm"],
                                    density_g_cm3=cfg.get("density_g_cm3", WATER_DENSITY_G_CM3))
    return Scene(f"water-box-{model}", system, x, np.zeros_like(x), f"{cfg['n_waters']} rigid {model} waters, PME",
                 topology, purpose="production", platform="CPU", invariants=("energy", "momentum"),
                 temperature=float(cfg["temperature"]), meta={"model": model})


def replica_states(box: Scene, cfg: dict, log=print, start=None):
    """(x, v) arrays of shape (replicas, N, 3): minimise, Langevin ``equilibrate_ps`` at ``temperature``,
    then one state every ``spacing_ps`` of further Langevin dynamics (replica r with seed ``seed + r``).  Each
    state's total momentum is set to zero (Langevin dynamics without a CMMotionRemover leaves the box drifting
    as a whole, ~0.04 nm/ps for 216 waters, which NVE keeps and which biases a diffusion coefficient); the
    chain itself continues from the Langevin state.  ``start``: the (x, v) arrays of replicas already built,
    which the chain continues from."""
    platform, props = "CPU", {"Threads": str(cfg.get("threads", 1))}
    t0 = time.perf_counter()
    seed = int(cfg["seed"])
    n_old = 0 if start is None else len(start[0])
    if not n_old:
        x = minimise(box.system, box.positions, platform=platform, properties=props, max_iterations=500)
        x, v = equilibrate(box.system, x, cfg["temperature"], cfg["equilibrate_ps"], seed, platform=platform,
                           properties=props)
        xs, vs = [x], [without_net_momentum(v, box.masses())]
    else:
        xs, vs = list(start[0]), list(start[1])
        x, v = xs[-1], vs[-1]
    for r in range(len(xs), int(cfg["replicas"])):
        x, v = equilibrate(box.system, x, cfg["temperature"], cfg["spacing_ps"], seed + r, platform=platform,
                           properties=props)
        xs.append(x)
        vs.append(without_net_momentum(v, box.masses()))
    log(f"{box.meta['model']}: {len(box.molecules)} waters, {len(xs)} replica states ({cfg['equilibrate_ps']} + "
        f"{cfg['spacing_ps']} ps apart of Langevin dynamics; {len(xs) - n_old} new, "
        f"{time.perf_counter() - t0:.0f} s)")
    return np.array(xs), np.array(vs)


def force_evals_per_step(method: str) -> int:
    """Force evaluations per step of a row's method (``rigid:<method>`` too), under constraints."""
    return Row(method, 1.0).evals_per_step(constraints=True)


def steps_per_sample(step_fs: float, sample_fs: float) -> int:
    return max(1, int(round(sample_fs / step_fs)))


def make_engine(box, x, v, method, step_fs, threads):
    """The running row ``method`` at ``step_fs`` (``rigid:<method>``: the rigid-body engine) from (x, v)."""
    return RowEngine(box, x, v, Row(method, float(step_fs)), threads=threads)


def run_nve(box: Scene, x, v, method: str, step_fs: float, cfg: dict):
    """One NVE run; returns (arrays, info).  arrays: t (ps, from the end of settling), T_trans, T_rot (K),
    pe and etot (kJ/mol).  info: wall_s, steps, force_evals, status ("ok", or "blew up at step S")."""
    every = steps_per_sample(step_fs, cfg["sample_fs"])
    dt_sample = every * step_fs * 1e-3
    settle = int(round(cfg["settle_ps"] / dt_sample))
    n_samples = int(round(cfg["length_ps"] / dt_sample)) + 1
    m, molecules, n_constraints = box.masses(), box.molecules, box.system.getNumConstraints()
    t0 = time.perf_counter()
    eng = make_engine(box, x, v, method, step_fs, cfg.get("threads", 1))
    out = {k: np.full(n_samples, np.nan) for k in ("t", "T_trans", "T_rot", "pe", "etot")}
    status, steps = "ok", 0
    for i in range(-settle, n_samples):
        if i > -settle:
            eng.step(every)
            steps += every
        if i < 0:
            continue
        xs, vs, pe = eng.sample()
        kt = kinetic_temperatures(xs, vs, m, molecules, True, n_constraints)
        ke = kinetic_energy(vs, m)
        out["t"][i], out["T_trans"][i], out["T_rot"][i] = i * dt_sample, kt.translational, kt.rotational
        out["pe"][i], out["etot"][i] = pe, pe + ke
        if not np.isfinite(pe + ke) or abs(kt.translational) > 1e5:
            status = f"blew up at step {steps}"
            break
    wall = time.perf_counter() - t0
    info = {"wall_s": wall, "steps": steps, "force_evals": steps * force_evals_per_step(method), "status": status,
            "sample_ps": dt_sample}
    return out, info
