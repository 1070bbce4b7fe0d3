"""Effective-energy drift of thermostatted runs next to the NVE drift of the same method and step
(``symprk nvt drift``): the NVT work-precision chart.

With the thermostat on, total energy + heat-bath energy (``computeHeatBathEnergy()``) is conserved but for the
integrator's own error, so its drift should be the NVE drift of the same method and step.  Scene: 216 rigid TIP3P
waters in a periodic box (PME, 0.9 nm cutoff, no CMMotionRemover; 648 atoms), CPU platform, minimised and
equilibrated at 300 K with Langevin dynamics; every replica starts from its own state (1 ps more Langevin
dynamics after the previous one), and the NVT and NVE runs of a replica start from that same state.  Per run, the
drift is the least-squares slope of the energy samples with its correlation-corrected standard error
(:func:`openmm_symprk.stats.drift`); replicas are combined with :func:`openmm_symprk.stats.combine` (the larger
of the within- and between-replica errors) and the NVT - NVE difference is taken replica by replica
(:func:`openmm_symprk.stats.paired`).  Unit: kT per ns per degree of freedom (3 N - constraints - 3), OpenMM's
unit for energy drift.

Rows: the package's methods at their usual steps (the native backend, thermostat tau 0.1 ps, every step), and
OpenMM's NoseHooverIntegrator (its own heat-bath energy) next to OpenMM's VerletIntegrator.
"""
from __future__ import annotations

import math
import time

import numpy as np
import openmm as mm
import openmm.unit as unit

from ...physics.temperature import R_KJ
from ...stats import combine, drift, paired
from ..core.rows import Row
from .rows import TEMPERATURE

KJ = unit.kilojoule_per_mole


def default_pairs(quick: bool = False) -> list:
    """[(NVT row, NVE row of the same method and step)]."""
    if quick:
        return [_ours("verlet", 2.0), _ours("omelyan-2", 4.0)]
    return [_ours("verlet", 1.0), _ours("verlet", 2.0), _ours("verlet", 3.0), _ours("omelyan-2", 4.0),
            _ours("pefrl", 4.0), _nose_hoover(2.0)]


def _ours(method, step):
    return ((f"{method} {step:g} fs", Row.parse(f"{method} {step:g} fs SVR 0.1 ps native")),
            (f"{method} {step:g} fs NVE", Row.parse(f"{method} {step:g} fs native")))


def _nose_hoover(step):
    return ((f"NoseHoover {step:g} fs", Row.parse(f"nose-hoover {step:g} fs 1/ps")),
            (f"OpenMM Verlet {step:g} fs", Row.parse(f"openmm-verlet {step:g} fs")))


def pairs_from(text: str) -> list:
    """Pairs from "method@step_fs,..." (catalogue names; ``nosehoover`` for OpenMM's NoseHooverIntegrator next to
    its VerletIntegrator); ValueError naming a bad entry."""
    from ...methods.catalogue import get_method

    out = []
    for item in (s.strip() for s in text.split(",") if s.strip()):
        method, _, step = item.partition("@")
        try:
            step_fs = float(step)
        except ValueError:
            step_fs = float("nan")
        if not step_fs > 0:
            raise ValueError(f"row {item!r}: write method@step_fs, e.g. omelyan-2@4 or nosehoover@2")
        out.append(_nose_hoover(step_fs) if method == "nosehoover" else _ours(get_method(method).name, step_fs))
    if not out:
        raise ValueError(f"no rows in {text!r}: write method@step_fs,..., e.g. verlet@2,omelyan-2@4")
    return out


def water_box_scene(equilibrate_ps: float, threads: int):
    """(system, positions, velocities) of the drift scene: 216 rigid TIP3P waters, PME 0.9 nm, at 300 K."""
    from ...systems.prepare import equilibrate, minimise
    from ...systems.scenes import water_box

    system, _, x = water_box("tip3p", n_waters=216, cutoff_nm=0.9)
    props = {"Threads": str(threads)}
    x = minimise(system, x, "CPU", tolerance=10.0, max_iterations=200, properties=props)
    x, v = equilibrate(system, x, TEMPERATURE, equilibrate_ps, seed=3, properties=props)
    return system, x, v


def energy_series(row: Row, system, x, v, length_ps: float, sample_fs: float, seed: int, threads: int):
    """(t in ps, effective energy in kJ/mol) of one run: total energy, + heat-bath energy for a thermostat that has
    one.  Stops at the first non-finite energy (a blow-up: the series so far is returned)."""
    ig = row.build(system, seed=seed)
    ctx = mm.Context(system, ig, mm.Platform.getPlatformByName("CPU"), {"Threads": str(threads)})
    try:
        ctx.setPositions(x)
        ctx.setVelocities(v)
        every = max(1, int(round(sample_fs / row.step_fs)))
        samples = int(round(length_ps * 1000.0 / (row.step_fs * every)))
        heat = ig.computeHeatBathEnergy if row.has_heat_bath else None
        t, e = [], []
        for _ in range(samples):  # from the end of the first block: OpenMM 8.6's NoseHooverIntegrator
            ig.step(every)        # segfaults in computeHeatBathEnergy() before its first step
            st = ctx.getState(getEnergy=True)
            value = (st.getPotentialEnergy() + st.getKineticEnergy()).value_in_unit(KJ)
            if heat is not None:
                value += heat().value_in_unit(KJ)
            if not math.isfinite(value):
                break
            t.append(st.getTime().value_in_unit(unit.picosecond))
            e.append(value)
        return np.array(t), np.array(e)
    finally:
        del ctx


def run(quick: bool = False, replicas: int | None = None, length_ps: float | None = None, threads: int = 2,
        pairs=None, log=print) -> dict:
    """Measure every pair over ``replicas`` replicas; prints the table and returns it as JSON-ready data."""
    from ...systems.prepare import equilibrate
    from ...systems.properties import thermostat_degrees_of_freedom

    replicas = replicas or (1 if quick else 3)
    length_ps = length_ps or (0.2 if quick else 20.0)
    sample_fs = 8.0 if quick else 20.0
    pairs = pairs or default_pairs(quick)
    system, x, v = water_box_scene(0.1 if quick else 2.0, threads)
    dof = thermostat_degrees_of_freedom(system, isolated=False)
    per_dof = 1000.0 / (R_KJ * TEMPERATURE * dof)  # kJ/mol/ps -> kT/ns/DOF
    raw = {name: {} for pair in pairs for name, _ in pair}  # row -> {replica: (slope, se)}
    failed = {}
    start = time.perf_counter()
    for r in range(replicas):
        if r:
            x, v = equilibrate(system, x, TEMPERATURE, 0.1 if quick else 1.0, seed=100 + r,
                               properties={"Threads": str(threads)})
        for pair in pairs:
            for name, row in pair:
                t, e = energy_series(row, system, x, v, length_ps, sample_fs, seed=10 + r, threads=threads)
                if len(t) < 3 or t[-1] < 0.999 * length_ps - 1e-9:
                    failed[name] = f"non-finite energy at {t[-1] if len(t) else 0:.3g} ps (replica {r})"
                    continue
                d = drift(t, e)
                raw[name][r] = (d.slope * per_dof, d.se * per_dof)
        log(f"replica {r + 1}/{replicas} done ({time.perf_counter() - start:.0f} s)")
    evals = {name: row.evals_per_step(True) for pair in pairs for name, row in pair}
    rows = []
    for (nvt, nvt_row), (nve, _) in pairs:
        entry = {"nvt_row": nvt, "nve_row": nve, "step_fs": nvt_row.step_fs, "evals": evals[nvt],
                 "evals_per_ps": evals[nvt] * 1000.0 / nvt_row.step_fs}
        for key, name in (("nvt", nvt), ("nve", nve)):
            got = raw[name]
            entry[key] = combine([got[k][0] for k in sorted(got)], [got[k][1] for k in sorted(got)]).as_dict() \
                if got and name not in failed else None
            entry[key + "_failed"] = failed.get(name)
        diff = paired(raw[nvt], raw[nve])
        entry["difference"] = diff.as_dict() if diff is not None and entry["nvt"] and entry["nve"] else None
        rows.append(entry)
    result = {"scene": f"216 rigid TIP3P waters, PME 0.9 nm, {system.getNumParticles()} atoms, periodic",
              "platform": "CPU", "threads": threads, "temperature_K": TEMPERATURE, "dof": dof,
              "length_ps": length_ps, "replicas": replicas, "sample_fs": sample_fs, "rows": rows,
              "openmm": mm.version.full_version}
    log(format_table(result))
    return result


def _est(d) -> str:
    return f"{d['mean']:+9.4f} ± {d['se']:.4f}" if d else f"{'failed':>18s}"


def format_table(result: dict) -> str:
    lines = [f"effective-energy drift, kT/ns/DOF ({result['dof']} DOF): {result['scene']}, {result['platform']} "
             f"({result['threads']} threads), {result['replicas']} replica(s) x {result['length_ps']:g} ps, "
             f"T = {result['temperature_K']:g} K",
             f"  {'NVT row':18s} {'f/ps':>6s} {'NVT drift':>18s} {'NVE drift (same step)':>22s} "
             f"{'NVT - NVE (paired)':>20s}"]
    for r in result["rows"]:
        lines.append(f"  {r['nvt_row']:18s} {r['evals_per_ps']:6.0f} {_est(r['nvt'])} {_est(r['nve']):>22s} "
                     f"{_est(r['difference']):>20s}")
        for key in ("nvt_failed", "nve_failed"):
            if r[key]:
                lines.append(f"    {r['nvt_row' if key == 'nvt_failed' else 'nve_row']}: {r[key]}")
    lines.append("  NVT: total + heat-bath energy; NVE row of NoseHoover: OpenMM's VerletIntegrator; ± one standard "
                 "error (the larger of within- and between-replica)")
    return "\n".join(lines)
