"""One fidelity run (the OpenMM side): a row from a replica state, its frames, its observables.

A run settles for ``settle_ps``, stores positions and velocities every ``omega_fs`` (rounded to whole steps,
at most the step itself) for ``omega_ps`` (the angular velocities, whose correlation lives within 0.1 ps),
then samples every ``sample_fs`` for ``length_ps``: the kinetic temperatures (:mod:`openmm_symprk.physics.temperature`,
3 N - 3 translational degrees of freedom when the row keeps the total momentum), potential and effective energy
(total + heat bath), the molecules' centres of mass, dipole and H-H unit vectors, and every ``rdf_every``-th
frame's oxygen positions.  Frames are reduced in the worker; what is kept is each observable with its error
(:mod:`..observables`), the time series of the equipartition study (t, T_trans, T_rot, pe, etot) and the curves.
The row runs in :class:`~...core.engine.RowEngine` (a leapfrog integrator from v(-h/2): the positions of velocity
Verlet from the replica state, so OpenMM's NVE rows keep the replica's energy).
"""
from __future__ import annotations

import time

import numpy as np
import openmm as mm
import openmm.unit as unit

from ....analysis.angular import angular_velocities
from ....analysis.molecules import centre_of_mass_trajectory
from ....analysis.reorientation import atom_vectors, dipole_vectors
from ....physics.momenta import kinetic_energy
from ....physics.temperature import kinetic_temperatures
from ...core.engine import RowEngine
from ..observables import observables
from ..rowspec import describe, to_row

__all__ = ["run_row", "replica_seed", "charges", "unstable", "UNSTABLE"]

#: How a run that blew up is recorded (and reported): "unstable at step N" (N counted from the run's start).
UNSTABLE = "unstable at step {}"


def unstable(exc: Exception, steps_before: int, n: int) -> str | None:
    """The status of a run whose ``n`` steps from step ``steps_before`` raised ``exc``: "unstable at step N" where
    ``exc`` says the integration blew up (this package's SimulationBlowUpError names the step of its call;
    OpenMM's integrators raise an OpenMMException about NaN coordinates: the chunk's last step is given, "by
    step N"), else None (an error that is not an instability)."""
    import re

    from ....integrators import SimulationBlowUpError

    if isinstance(exc, SimulationBlowUpError):
        m = re.search(r"at integrator step (\d+)", str(exc))
        # the integrator counts from its creation, which is the run's start (one integrator per run)
        return UNSTABLE.format(int(m.group(1)) if m else steps_before + n)
    if isinstance(exc, mm.OpenMMException) and "nan" in str(exc).lower():
        return UNSTABLE.format(f"{steps_before + 1}-{steps_before + n}" if n > 1 else steps_before + 1)
    return None


def replica_seed(cfg: dict, replica: int) -> int:
    """The random seed of a stochastic row's run on ``replica`` (> 0: reproducible)."""
    return int(cfg["seed"]) * 1000 + 17 * int(replica) + 1


def charges(system) -> np.ndarray:
    nb = next(f for f in system.getForces() if isinstance(f, mm.NonbondedForce))
    return np.array([nb.getParticleParameters(i)[0].value_in_unit(unit.elementary_charge)
                     for i in range(system.getNumParticles())])


def run_row(scene, x, v, row: dict, cfg: dict, replica: int):
    """One run of ``row`` from the replica state (x, v) of ``scene``; returns (arrays, info).  info: status
    ("ok" or "unstable at step S", :func:`unstable`), wall_s, steps, force_evals, obs {key: [value, se] or None}, notes."""
    t0 = time.perf_counter()
    spec = to_row(row, cfg["temperature"])
    eng = RowEngine(spec, scene, x, v, threads=cfg.get("threads", 1), seed=replica_seed(cfg, replica))
    info = describe(row)
    h = info["step_fs"]
    mols, m, q = scene.molecules, eng.masses, charges(scene.system)
    n_constraints = scene.system.getNumConstraints()
    box = float(scene.system.getDefaultPeriodicBoxVectors()[0][0].value_in_unit(unit.nanometer))  # cubic
    steps, status = 0, "ok"

    class Unstable(Exception):
        pass

    def advance(n):
        nonlocal steps, status
        try:
            eng.step(n)
        except Exception as exc:  # noqa: BLE001 - an instability is recorded, anything else raised
            why = unstable(exc, steps, n)
            if why is None:
                raise
            status = why
            raise Unstable() from None
        steps += n

    every_w, every = spec.steps_for(cfg["omega_fs"]), spec.steps_for(cfg["sample_fs"])
    n = int(round(cfg["length_ps"] * 1000.0 / (every * h))) + 1
    keys = ("t", "T_trans", "T_rot", "pe", "etot")
    out = {k: np.full(n, np.nan) for k in keys}
    xs_w, vs_w = [], []
    try:
        advance(max(0, int(round(cfg["settle_ps"] * 1000.0 / h))))
        for i in range(int(round(cfg["omega_ps"] * 1000.0 / (every_w * h))) + 1):
            if i:
                advance(every_w)
            xw, vw, _, _ = eng.sample(energy=False, on_step=True)
            xs_w.append(xw)
            vs_w.append(vw)
    except Unstable:
        pass
    if status != "ok":
        info = {"status": status, "steps": steps, "force_evals": steps * info["evals_per_step"],
                "wall_s": time.perf_counter() - t0}
        return {k: out[k] for k in keys}, info
    com, dip, hh, oxygen = [], [], [], []
    for i in range(n):
        if i:
            try:
                advance(every)
            except Unstable:
                break
        xs, vs, pe, _ = eng.sample(on_step=True)
        kt = kinetic_temperatures(xs, vs, m, mols, info["keeps_momentum"], n_constraints)
        bath = eng.heat_bath()
        etot = pe + kinetic_energy(vs, m) + (bath or 0.0)
        out["t"][i], out["T_trans"][i], out["T_rot"][i], out["pe"][i], out["etot"][i] = \
            i * every * h * 1e-3, kt.translational, kt.rotational, pe, etot
        if not np.isfinite(etot) or abs(kt.translational) > 1e5:
            status = UNSTABLE.format(steps)
            break
        frame = xs[None]
        com.append(centre_of_mass_trajectory(frame, m, mols)[0])
        dip.append(dipole_vectors(frame, mols, q)[0])
        hh.append(atom_vectors(frame, mols, 1, 2)[0])
        if i % int(cfg["rdf_every"]) == 0:
            oxygen.append(xs[[g[0] for g in mols]])
    info = {"status": status, "steps": steps, "force_evals": steps * info["evals_per_step"],
            "sample_ps": every * h * 1e-3, "omega_ps_between": every_w * h * 1e-3}
    if status != "ok":
        info["wall_s"] = time.perf_counter() - t0
        return {k: out[k] for k in keys}, info
    xs_w, vs_w = np.array(xs_w), np.array(vs_w)
    series = dict(out, com=np.array(com), dip=np.array(dip), hh=np.array(hh), oxygen=np.array(oxygen),
                  omega=angular_velocities(xs_w, vs_w, m, mols, frame="space"), dt_omega=every_w * h * 1e-3)
    obs, curves, notes = observables(series, cfg, len(mols), box, describe(row)["effective_energy"])
    info.update(obs=obs, notes=notes, wall_s=time.perf_counter() - t0)
    if "omega_acf" in curves:  # the curve the features are read from (a reduced result: a few hundred numbers)
        info.update(omega_acf=[round(float(c), 7) for c in curves["omega_acf"]], omega_acf_dt_ps=every_w * h * 1e-3)
    return dict({k: out[k] for k in keys}, **curves), info
