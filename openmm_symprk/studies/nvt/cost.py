"""Time per step of NVT integrators against OpenMM's LangevinMiddleIntegrator, in the same run (``symprk nvt cost``).

Every row is timed with :func:`openmm_symprk.studies.core.timing.time_rows` (the rows take turns in blocks of about
the same duration, round after round), on the CPU platform with a fixed thread count (or another platform: ``--platform OpenCL``), from one shared state.  The
ratio of a row is the median over rounds of its time per step over LangevinMiddleIntegrator's (2 fs) in the same
round, with the quartiles (blocks run moments apart share the machine's load); rows that replace another OpenMM
integrator (MTSLangevinIntegrator, VerletIntegrator) also get the ratio to it.  "per ps" divides by the step
size, for rows whose method is run at a longer step.  The thermostat's own cost follows from the rows without
it: (t[verlet + thermostat] - t[verlet NVE]) / 2 per event (two half events per step); the "... middle" rows
time the middle placement (one whole event per step) beside the ends one.

Scenes: the periodic rigid TIP3P water box of the bench (``water-box-pme``, about 5,800 atoms, PME 0.9 nm) and
the solvated villin headpiece (``villin-pme``, 8,867 atoms, HBonds, rigid water; equilibrated only briefly: a
timing needs no equilibrium), the PME reciprocal space in force group 1 for the MTS rows.
``--no-forces`` removes every force (constraints stay): what is left is the integrators' own work, where the
thermostat event's cost shows.  Not a test: nothing is asserted on the times.
"""
from __future__ import annotations

import os

import numpy as np
import openmm as mm

from ..core.engine import RowEngine
from ..core.timing import time_rows
from .rows import cost_rows
from ...support.errors import InputError

BASELINE = "LangevinMiddle"


def scene(name: str, quick: bool):
    """(title, system, positions, velocities) of a cost scene; ``quick``: a small water box / short equilibration."""
    from ...systems.forcegroups import split_forces
    from ..core import scenes as named

    if name == "water":
        sc = named.water_box_pme(box_nm=2.2 if quick else 3.9)
        split_forces(sc.system, slow="reciprocal")
    elif name == "villin":
        sc = named.villin_pme(equilibrate_ps=0.02 if quick else 0.2)
    else:
        raise InputError(f"unknown cost scene {name!r}; known: water, villin")
    return f"{sc.name}: {sc.description}", sc.system, sc.positions, sc.velocities


def measure(system, positions, velocities, rows, steps, rounds: int, threads: int = 2,
            platform: str = "CPU") -> dict:
    """{row name: (Timing, force evaluations per step)}; rows take turns (:func:`..core.timing.time_rows`, 3 steps
    of warm-up).  ``steps``: steps per block (an int), or a float number of seconds: each row's block is sized to
    last about that long, so that every row gets equally many short blocks, the likelier to catch a quiet moment of
    a shared machine."""
    engines = {name: RowEngine(row, system, positions, velocities, platform=platform, threads=threads, start=False)
               for name, row, _ in rows}
    evals = {name: row.evals_per_step(system.getNumConstraints() > 0) for name, row, _ in rows}
    return {k: (t, evals[k]) for k, t in time_rows(engines, steps, rounds, warmup=3).items()}


def paired_ratio(row, base) -> tuple:
    """(median, 25th, 75th percentile) over rounds of the row's block time over the baseline's block time of the
    same round: blocks run moments apart see about the same load, so the round-by-round ratio is steadier than
    either time; the quartiles say how steady."""
    r = np.asarray(row.blocks) / np.asarray(base.blocks)
    return tuple(float(q) for q in np.percentile(r, [50, 25, 75]))


def ratios(measured: dict, rows) -> list:
    """One dict per row: seconds per step (fastest block), the ratio to the baseline (median of the round-by-round
    ratios, with quartiles, and fastest over fastest), per ps simulated, and the ratio to its peer."""
    base = measured[BASELINE][0]
    base_dt = next(r.step_fs for name, r, _ in rows if name == BASELINE)
    out = []
    for name, r, peer in rows:
        t, evals = measured[name]
        median, q25, q75 = paired_ratio(t, base)
        out.append({"row": name, "step_fs": r.step_fs, "evals": evals, "s_per_step": t.best, "ratio": median,
                    "ratio_q25": q25, "ratio_q75": q75, "ratio_best": t.best / base.best,
                    "ratio_per_ps": median * base_dt / r.step_fs, "peer": peer,
                    "peer_ratio": paired_ratio(t, measured[peer][0])[0] if peer else None})
    return out


def event_cost(table: list) -> float | None:
    """The cost of one half thermostat event as a fraction of a LangevinMiddle step, from verlet with and without
    the thermostat (two events per step); None without those rows."""
    by = {r["row"]: r for r in table}
    if "verlet + thermostat" not in by or "verlet (NVE)" not in by:
        return None
    return (by["verlet + thermostat"]["ratio"] - by["verlet (NVE)"]["ratio"]) / 2


def format_table(title: str, table: list) -> str:
    lines = [title, f"  {'integrator':34s} {'dt fs':>5s} {'f/step':>6s} {'ms/step':>8s} {'/ Langevin':>10s} "
                    f"{'quartiles':>13s} {'best/best':>9s} {'per ps':>7s} {'/ peer':>7s}"]
    for r in table:
        peer = f"{r['peer_ratio']:7.3f}" if r["peer_ratio"] is not None else f"{'':7s}"
        lines.append(f"  {r['row']:34s} {r['step_fs']:5.1f} {r['evals']:6d} {r['s_per_step'] * 1e3:8.3f} "
                     f"{r['ratio']:10.3f} {r['ratio_q25']:6.3f}-{r['ratio_q75']:.3f} {r['ratio_best']:9.3f} "
                     f"{r['ratio_per_ps']:7.3f} {peer}")
    e = event_cost(table)
    if e is not None:
        lines.append(f"  one half thermostat event: {e:+.3f} LangevinMiddle steps ((verlet + thermostat - verlet NVE) / 2)")
    lines.append(f"  ms/step: fastest block; / Langevin: median over rounds of the time per step over {BASELINE}"
                 f"Integrator's (2 fs)\n  in the same round (quartiles beside it); best/best: fastest over fastest; "
                 f"per ps: / Langevin per ps simulated;\n  / peer: the same median over the OpenMM row it replaces")
    return "\n".join(lines)


def run(scenes=("water", "villin"), quick: bool = False, steps=None, rounds: int | None = None,
        threads: int = 2, no_forces: bool = False, platform: str = "CPU", log=print) -> dict:
    """Measure and print the cost table of every scene; returns {scene: table}.  ``no_forces``: every force
    removed (constraints stay), so the table times the integrators' own work: the thermostat event's cost.
    ``platform``: "CPU" (``threads`` threads) or another OpenMM platform, e.g. "OpenCL" (PoCL on a CPU)."""
    from ... import plugin

    if not plugin.available():
        raise plugin.NativeUnavailableError(f"the native backend is unavailable: {plugin.unavailable_reason()}")
    where = f"platform CPU, {threads} threads" if platform == "CPU" else f"platform {platform}"
    log(f"openmm {mm.version.full_version}, {where}, load average before "
        f"{os.getloadavg()[0]:.2f} (other processes slow some blocks; each row keeps its fastest)")
    rows = [r for r in cost_rows() if not (no_forces and r[1].mts)]  # no forces, no groups
    out = {}
    for name in scenes:
        title, system, x, v = scene(name, quick)
        if no_forces:
            while system.getNumForces():
                system.removeForce(0)
            title += ", no forces (the integrators' own work)"
        n = steps or (0.01 if quick else 0.3)
        k = rounds or (2 if quick else 15)
        best = measure(system, x, v, rows, n, k, threads, platform)
        out[name] = ratios(best, rows)
        blocks = f"{n} steps" if isinstance(n, int) else f"blocks of ~{n:g} s"
        log(format_table(f"{title}: {k} rounds, {blocks}, fastest block per row", out[name]))
    log(f"load average after: {os.getloadavg()[0]:.2f}")
    return out
