"""The main example: a spinning rigid-water cluster in vacuum, our integrators beside OpenMM's.

It runs where users run, OpenMM's CPU platform (Reference only where CPU is missing, and it says so).  There
OpenMM's integrators keep the angular momentum of an isolated cluster only to the platform's single-precision
forces; ours with ``exact_momentum`` keep it to round-off, under NVE and under the thermostat alike.

Prints, per row (:data:`ROWS`): the backend it ran on, energy error (for a thermostatted row: of the energy
plus the heat-bath energy), linear and angular momentum change, force evaluations per step and the wall-time
ratio to OpenMM's VerletIntegrator measured in the same run (the integrators take turns block by block,
:mod:`.core.timing`).
"""
from __future__ import annotations

import argparse
from dataclasses import dataclass

import numpy as np
import openmm as mm

from ..physics import angular_momentum, linear_momentum
from ..integrators.thermostat import DEFAULT_COLLISION_TIME
from ..systems.properties import degrees_of_freedom
from ..systems.scenes import water_cluster
from .core import platforms
from .core.options import positive
from .core.engine import RowEngine
from .core.rows import Row
from .core.timing import interleaved

__all__ = ["ROWS", "DemoRow", "run_demo", "default_platform", "build_parser", "run"]

#: The demo's rows, in order: (name printed, row label without its step; :class:`~.core.rows.Row`).  The first row is
#: the timing reference.  The thermostatted rows run at 300 K: ours with the package's default collision time, OpenMM's
#: LangevinMiddleIntegrator with friction 1/ps.
ROWS = (
    ("OpenMM VerletIntegrator", "openmm-verlet"),
    ("symprk verlet", "verlet"),
    ("symprk verlet exact_momentum", "verlet exact-momentum"),
    ("symprk yoshida-4", "yoshida-4"),
    ("OpenMM LangevinMiddle 300 K", "langevin friction 1/ps"),
    ("symprk verlet 300 K exact_momentum", f"verlet SVR {DEFAULT_COLLISION_TIME:g} ps exact-momentum"),
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
    names = platforms.names() if names is None else names
    if "CPU" in names:
        return "CPU", ""
    return "Reference", f"OpenMM's CPU platform is not available here (platforms: {', '.join(names)}); " \
                        "running on Reference as a fallback."


class _Tracker:
    """One row running on its own Context (:class:`~.core.engine.RowEngine`, from the scene's state as it is: the
    leapfrog row's velocities lag), with its running error figures."""

    def __init__(self, name, engine, n_dof):
        self.name, self.eng, self.n_dof = name, engine, n_dof
        self.backend = engine.integrator.backend if engine.row.is_ours else "OpenMM"
        self.evals, self.nvt = engine.row.evals_per_step(True), bool(engine.row.thermostat)
        self.e0, self.p0, self.l0 = self._measure()
        self.worst = self.dp = self.dl = 0.0

    def _measure(self):
        # the effective energy of a thermostatted row is E + heat-bath energy; OpenMM's Langevin has none
        x, v, pe, ke = self.eng.sample()
        m = self.eng.masses
        return pe + ke + (self.eng.heat_bath() or 0.0), linear_momentum(v, m), angular_momentum(x, v, m, about="origin")

    def record(self):
        e, p, l = self._measure()
        self.worst = max(self.worst, abs(e - self.e0) / self.n_dof)
        self.dp = max(self.dp, float(np.linalg.norm(p - self.p0)))
        self.dl = max(self.dl, float(np.linalg.norm(l - self.l0) / np.linalg.norm(self.l0)))

    @property
    def energy_error(self):
        return None if self.eng.heat_bath() is None else self.worst


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
    specs = ROWS if methods is None else (ROWS[0],) + tuple((f"symprk {m}", m) for m in methods)
    scene = water_cluster(n_waters)
    chunk = max(1, min(chunk, steps))
    if note:
        out(note)
    out(f"Scene: {scene.description}; {steps} steps of {step_fs:g} fs on {platform}.")
    out("OpenMM's VerletIntegrator is leapfrog: its State velocities lag half a step, so x_n x v_(n-1/2) is")
    out("not an invariant for it; our integrators report synchronous (x_n, v_n).\n")
    trackers = []
    for name, label in specs:
        row = Row.parse(label, step_fs=step_fs)
        if row.is_ours:
            row = row.replace(backend=backend)
            name = name.replace(f"symprk {label.split()[0]}", f"symprk {row.method}", 1)
        eng = RowEngine(row, scene, platform=platform, threads=None, start=False, quiet=False)
        trackers.append(_Tracker(name, eng, degrees_of_freedom(scene.system)))
    by_name = {tr.name: tr for tr in trackers}
    timings = interleaved({tr.name: tr.eng.step for tr in trackers}, chunk, rounds=max(1, steps // chunk),
                          after=lambda name: by_name[name].record())
    rows = [DemoRow(tr.name, tr.backend, tr.energy_error, tr.dp, tr.dl, tr.evals, timings[tr.name].best, tr.nvt)
            for tr in trackers]
    for line in _table(rows, max(28, *(len(r.name) for r in rows))):
        out(line)
    out("\n|dE| in kJ/mol per degree of freedom; |dP| in Da nm/ps; time per step relative to OpenMM's "
        "VerletIntegrator,\neach the fastest of its blocks of steps, the integrators taking turns block by block.")
    if any(r.nvt for r in rows):
        out("Rows at 300 K are NVT, where the energy is not conserved: for ours |dE| is that of the energy\n"
            "plus the heat-bath energy (computeHeatBathEnergy), which is; OpenMM's LangevinMiddleIntegrator (friction\n"
            "1/ps) has no heat-bath energy (-).  Our thermostat rescales the velocities relative to the\n"
            "cluster's rigid motion, so P and L stay; Langevin's random forces change both.")
    return rows


def build_parser(prog: str = "symprk demo"):
    p = argparse.ArgumentParser(prog=prog, description="spinning rigid-water cluster: conservation vs OpenMM's "
                                                       "Verlet and Langevin")
    p.add_argument("--method", nargs="+", default=None,
                   help="catalogue names, each an NVE row beside OpenMM's Verlet (default: the demo's rows)")
    p.add_argument("--waters", type=positive(int), default=64)
    p.add_argument("--steps", type=positive(int), default=2000)
    p.add_argument("--step-fs", type=positive(float), default=2.0)
    p.add_argument("--platform", default=None, help="default: CPU (Reference where CPU is missing)")
    p.add_argument("--backend", default="auto", choices=("auto", "native", "custom"))
    return p


def run(args):
    run_demo(methods=args.method, n_waters=args.waters, steps=args.steps, step_fs=args.step_fs,
             platform=None if args.platform is None else platforms.check(args.platform), backend=args.backend)
