"""Time per step of NVT integrators against OpenMM's LangevinMiddleIntegrator, in the same run (``symprk nvt cost``).

Every row is timed with :func:`openmm_symprk.studies.timing.interleaved` (the rows take turns, round after round,
and each keeps its fastest block), on the CPU platform with a fixed thread count, from one shared state.  The
ratio of a row is its time per step over LangevinMiddleIntegrator's (2 fs) in the same run; rows that replace
another OpenMM integrator (MTSLangevinIntegrator, VerletIntegrator) also get the ratio to it.  "per ps" divides
by the step size, for rows whose method is run at a longer step.  The thermostat's own cost follows from the
rows without it: (t[verlet + thermostat] - t[verlet NVE]) / 2 per event (two half events per step).

Scenes: the periodic rigid TIP3P water box of the bench (``water-box-pme``, about 5,800 atoms, PME 0.9 nm) and
the solvated villin headpiece (``villin-pme``, 8,867 atoms, HBonds, rigid water; equilibrated only briefly: a
timing needs no equilibrium), the PME reciprocal space in force group 1 for the MTS rows.
Not a test: nothing is asserted on the times.
"""
from __future__ import annotations

import os

import openmm as mm

from ..timing import interleaved
from .rows import MTS_GROUPS, Row, build

BASELINE = "LangevinMiddle"


def default_rows() -> list:
    """The rows of the cost table: OpenMM's thermostats, ours at interval 1 and 10, NVE for reference, MTS."""
    mts = "+".join(f"{g}x{n}" for g, n in MTS_GROUPS)
    return [
        Row(BASELINE, "openmm-langevin", 2.0),
        Row("NoseHoover (chain 3)", "openmm-nosehoover", 2.0),
        Row("DPD", "openmm-dpd", 2.0),
        Row("OpenMM Verlet (NVE)", "openmm-verlet", 2.0),
        Row("verlet (NVE)", "symprk", 2.0, "verlet", nvt=False, peer="OpenMM Verlet (NVE)"),
        Row("verlet + thermostat", "symprk", 2.0, "verlet"),
        Row("verlet + thermostat /10", "symprk", 2.0, "verlet", interval=10),
        Row("omelyan-2 + thermostat", "symprk", 4.0, "omelyan-2"),
        Row(f"MTSLangevin {mts}", "openmm-mtslangevin", 4.0),
        Row(f"verlet MTS {mts} + thermostat", "symprk", 4.0, "verlet", mts=True, peer=f"MTSLangevin {mts}"),
    ]


def scene(name: str, quick: bool):
    """(title, system, positions, velocities) of a cost scene; ``quick``: a small water box / short equilibration."""
    from ...systems.forcegroups import split_forces
    from ..bench import registry

    if name == "water":
        sc = registry.water_box_pme(box_nm=2.2 if quick else 3.9)
        split_forces(sc.system, slow="reciprocal")
    elif name == "villin":
        sc = registry.villin_pme(equilibrate_ps=0.02 if quick else 0.2)
    else:
        raise ValueError(f"unknown cost scene {name!r}; known: water, villin")
    return f"{sc.name}: {sc.description}", sc.system, sc.positions, sc.velocities


def measure(system, positions, velocities, rows, steps: int, rounds: int, threads: int = 2,
            platform: str = "CPU") -> dict:
    """{row name: (seconds per step of the fastest block, force evaluations per step)}; rows take turns."""
    plat = mm.Platform.getPlatformByName(platform)
    props = {"Threads": str(threads)} if platform == "CPU" else {}
    contexts, evals = {}, {}
    for row in rows:
        ig, evals[row.name] = build(row, system, seed=1)
        ctx = mm.Context(system, ig, plat, props)
        ctx.setPositions(positions)
        ctx.setVelocities(velocities)
        ig.step(3)  # warm-up: neighbour lists, kernels, caches
        contexts[row.name] = (ctx, ig)

    def stepper(ctx, ig):
        def advance(n):
            ig.step(n)
            ctx.getState(getEnergy=False)  # the work is done (a no-op on CPU, a sync elsewhere)
        return advance

    timings = interleaved({k: stepper(*v) for k, v in contexts.items()}, steps, rounds=rounds)
    return {k: (t.best, evals[k]) for k, t in timings.items()}


def ratios(best: dict, rows) -> list:
    """One dict per row: seconds per step, ratio per step and per ps to the baseline, ratio to its peer."""
    base = best[BASELINE][0]
    base_dt = next(r.step_fs for r in rows if r.name == BASELINE)
    out = []
    for r in rows:
        t, evals = best[r.name]
        out.append({"row": r.name, "step_fs": r.step_fs, "evals": evals, "s_per_step": t, "ratio": t / base,
                    "ratio_per_ps": (t / r.step_fs) / (base / base_dt),
                    "peer": r.peer, "peer_ratio": t / best[r.peer][0] if r.peer else None})
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
                    f"{'per ps':>7s} {'/ peer':>7s}"]
    for r in table:
        peer = f"{r['peer_ratio']:7.3f}" if r["peer_ratio"] is not None else f"{'':7s}"
        lines.append(f"  {r['row']:34s} {r['step_fs']:5.1f} {r['evals']:6d} {r['s_per_step'] * 1e3:8.3f} "
                     f"{r['ratio']:10.3f} {r['ratio_per_ps']:7.3f} {peer}")
    e = event_cost(table)
    if e is not None:
        lines.append(f"  one half thermostat event: {e:+.3f} LangevinMiddle steps "
                     f"((verlet + thermostat - verlet NVE) / 2)")
    lines.append(f"  / Langevin: time per step over {BASELINE}Integrator's (2 fs) in the same run; per ps: the same per "
                 f"ps simulated; / peer: over the OpenMM row it replaces")
    return "\n".join(lines)


def run(scenes=("water", "villin"), quick: bool = False, steps: int | None = None, rounds: int | None = None,
        threads: int = 2, log=print) -> dict:
    """Measure and print the cost table of every scene; returns {scene: table}."""
    from ... import plugin

    if not plugin.available():
        raise RuntimeError(f"the native backend is unavailable: {plugin.unavailable_reason()}")
    log(f"openmm {mm.version.full_version}, platform CPU, {threads} threads, load average before "
        f"{os.getloadavg()[0]:.2f} (other processes slow some blocks; each row keeps its fastest)")
    rows = default_rows()
    out = {}
    for name in scenes:
        title, system, x, v = scene(name, quick)
        n = steps or (4 if quick else (40 if name == "water" else 25))
        k = rounds or (2 if quick else 5)
        best = measure(system, x, v, rows, n, k, threads)
        out[name] = ratios(best, rows)
        log(format_table(f"{title}: {k} rounds of {n} steps, fastest block", out[name]))
    log(f"load average after: {os.getloadavg()[0]:.2f}")
    return out
