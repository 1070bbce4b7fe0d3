"""The main example: a spinning rigid-water cluster in vacuum, our integrators beside OpenMM's.

It runs where users run, OpenMM's CPU platform (Reference only where CPU is missing, and it says so).  There
OpenMM's integrators keep the angular momentum of an isolated cluster only to the platform's single-precision
forces; ours with ``exact_momentum`` keep it to round-off, under NVE and under the thermostat alike.

Prints, per row (:data:`ROWS`): the backend it ran on, energy error (for a thermostatted row: of the energy
plus the heat-bath energy), linear and angular momentum change, force evaluations per step and the wall-time
ratio to OpenMM's VerletIntegrator measured in the same run (the integrators take turns block by block,
:mod:`.timing`).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import openmm as mm
import openmm.unit as unit

from ..conservation.diagnostics import angular_momentum, linear_momentum
from ..integrators import SymplecticIntegrator
from ..systems.properties import degrees_of_freedom
from ..systems.scenes import water_cluster
from .timing import interleaved

__all__ = ["ROWS", "DemoRow", "run_demo", "default_platform"]

#: Target temperature (K) of the thermostatted rows.
NVT_TEMPERATURE = 300.0
#: Friction of OpenMM's LangevinMiddleIntegrator row (1/ps).
LANGEVIN_FRICTION = 1.0

#: The demo's rows, in order: (label, integrator, options).  ``openmm-verlet`` and ``openmm-langevin-middle`` are
#: OpenMM's own integrators; any other name is a catalogue method of :class:`SymplecticIntegrator`, built with
#: these options.  The first row is the timing reference.
ROWS = (
    ("OpenMM VerletIntegrator", "openmm-verlet", {}),
    ("symprk verlet", "verlet", {}),
    ("symprk verlet exact_momentum", "verlet", {"exact_momentum": True}),
    ("symprk yoshida-4", "yoshida-4", {}),
    ("OpenMM LangevinMiddle 300 K", "openmm-langevin-middle", {"temperature": NVT_TEMPERATURE}),
    ("symprk verlet 300 K exact_momentum", "verlet", {"temperature": NVT_TEMPERATURE, "exact_momentum": True}),
)


@dataclass
class DemoRow:
    name: str
    backend: str
    energy_error: float | None  # max |E - E0| / n_dof, kJ/mol (E plus the heat-bath energy under our thermostat;
    #                             None for OpenMM's Langevin row, which has no heat-bath energy)
    dP: float  # |P - P0|, Da nm/ps
    dL_rel: float  # |L - L0| / |L0|, about the origin (P = 0 so also about the centre of mass)
    evals_per_step: float
    seconds_per_step: float  # fastest block
    nvt: bool = False


def default_platform(names=None) -> tuple[str, str]:
    """(platform, note): CPU where this installation has it (``names``: the platform names, default OpenMM's),
    else Reference with a note saying why."""
    if names is None:
        names = [mm.Platform.getPlatform(i).getName() for i in range(mm.Platform.getNumPlatforms())]
    if "CPU" in names:
        return "CPU", ""
    return "Reference", f"OpenMM's CPU platform is not available here (platforms: {', '.join(names)}); " \
                        "running on Reference as a fallback."


def _build(engine: str, options: dict, h, system, backend: str):
    """(integrator, backend label, force evaluations per step) for one row."""
    if engine == "openmm-verlet":
        return mm.VerletIntegrator(h), "OpenMM", 1.0
    if engine == "openmm-langevin-middle":
        return mm.LangevinMiddleIntegrator(options["temperature"] * unit.kelvin, LANGEVIN_FRICTION / unit.picosecond,
                                           h), "OpenMM", 1.0
    ig = SymplecticIntegrator(h, engine, system=system, backend=backend, **options)
    return ig, ig.backend, ig.program_info.force_evals


class _Tracker:
    """One integrator on its own Context, with its running error figures."""

    def __init__(self, scene, integrator, platform, name, backend, evals_per_step, nvt):
        self.ig, self.name, self.backend, self.evals, self.nvt = integrator, name, backend, evals_per_step, nvt
        # the effective energy of a thermostatted row is E + heat-bath energy; OpenMM's Langevin has none
        self.heat_bath = getattr(integrator, "computeHeatBathEnergy", None) if nvt else None
        self.ctx = scene.context(integrator, platform)
        self.masses = scene.masses()
        self.n_dof = degrees_of_freedom(scene.system)
        self.e0, self.p0, self.l0 = self._measure()
        self.worst = self.dp = self.dl = 0.0

    def _measure(self):
        st = self.ctx.getState(getEnergy=True, getPositions=True, getVelocities=True)
        e = (st.getPotentialEnergy() + st.getKineticEnergy()).value_in_unit(unit.kilojoule_per_mole)
        if self.heat_bath is not None:
            e += self.heat_bath().value_in_unit(unit.kilojoule_per_mole)
        return e, linear_momentum(st, masses=self.masses), angular_momentum(st, about="origin", masses=self.masses)

    def record(self):
        e, p, l = self._measure()
        self.worst = max(self.worst, abs(e - self.e0) / self.n_dof)
        self.dp = max(self.dp, float(np.linalg.norm(p - self.p0)))
        self.dl = max(self.dl, float(np.linalg.norm(l - self.l0) / np.linalg.norm(self.l0)))

    @property
    def energy_error(self):
        return None if self.nvt and self.heat_bath is None else self.worst


def _table(rows, width):
    lines = [f"{'integrator':{width}s} {'backend':8s} {'max|dE|/dof':>12s} {'|dP|':>10s} {'|dL|/|L|':>10s} "
             f"{'f/step':>6s} {'time/Verlet':>11s}"]
    base = rows[0].seconds_per_step
    for r in rows:
        energy = "-" if r.energy_error is None else f"{r.energy_error:.3e}"
        lines.append(f"{r.name:{width}s} {r.backend:8s} {energy:>12s} {r.dP:10.2e} {r.dL_rel:10.2e} "
                     f"{r.evals_per_step:6.0f} {r.seconds_per_step / base:11.2f}")
    return lines


def run_demo(methods=None, n_waters: int = 64, steps: int = 2000, step_fs: float = 2.0, platform: str | None = None,
             chunk: int = 100, backend: str = "auto", out=print):
    """Run the demo and print its table; returns the :class:`DemoRow` list.

    ``methods``: None for the rows of :data:`ROWS`; else catalogue names, each an NVE row beside OpenMM's
    VerletIntegrator.  ``platform``: None for :func:`default_platform` (CPU, else Reference)."""
    note = ""
    if platform is None:
        platform, note = default_platform()
    mm.Platform.getPlatformByName(platform)  # a clear OpenMMException for an unknown platform, before any work
    specs = ROWS if methods is None else (ROWS[0],) + tuple((f"symprk {m}", m, {}) for m in methods)
    scene = water_cluster(n_waters)
    h = step_fs * unit.femtoseconds
    chunk = max(1, min(chunk, steps))
    if note:
        out(note)
    out(f"Scene: {scene.description}; {steps} steps of {step_fs:g} fs on {platform}.")
    out("OpenMM's VerletIntegrator is leapfrog: its State velocities lag half a step, so x_n x v_(n-1/2) is")
    out("not an invariant for it; our integrators report synchronous (x_n, v_n).\n")
    trackers = []
    for label, engine, options in specs:
        ig, used, evals = _build(engine, options, h, scene.system, backend)
        if engine not in ("openmm-verlet", "openmm-langevin-middle"):
            label = label.replace(f"symprk {engine}", f"symprk {ig.method_name}", 1)
        trackers.append(_Tracker(scene, ig, platform, label, used, evals, "temperature" in options))
    by_name = {tr.name: tr for tr in trackers}
    timings = interleaved({tr.name: tr.ig.step for tr in trackers}, chunk, rounds=max(1, steps // chunk),
                          after=lambda name: by_name[name].record())
    rows = [DemoRow(tr.name, tr.backend, tr.energy_error, tr.dp, tr.dl, tr.evals, timings[tr.name].best, tr.nvt)
            for tr in trackers]
    for line in _table(rows, max(28, *(len(r.name) for r in rows))):
        out(line)
    out("\n|dE| in kJ/mol per degree of freedom; |dP| in Da nm/ps; time per step relative to OpenMM's "
        "VerletIntegrator,\neach the fastest of its blocks of steps, the integrators taking turns block by block.")
    if any(r.nvt for r in rows):
        out(f"Rows at {NVT_TEMPERATURE:g} K are NVT, where the energy is not conserved: for ours |dE| is that of the "
            "energy\nplus the heat-bath energy (computeHeatBathEnergy), which is; OpenMM's LangevinMiddleIntegrator "
            f"(friction\n{LANGEVIN_FRICTION:g}/ps) has no heat-bath energy (-).  Our thermostat rescales the velocities "
            "relative to the\ncluster's rigid motion, so P and L stay; Langevin's random forces change both.")
    return rows
