"""The main example: a spinning rigid-water cluster in vacuum, our integrators beside OpenMM's Verlet.

Prints, per integrator: the backend it ran on, energy error, linear and angular momentum change, force
evaluations per step and the wall-time ratio to OpenMM's VerletIntegrator measured in the same run (the
integrators take turns block by block, :mod:`.timing`).
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


@dataclass
class DemoRow:
    name: str
    backend: str
    energy_error: float  # max |E - E0| / n_dof, kJ/mol
    dP: float  # |P - P0|, Da nm/ps
    dL_rel: float  # |L - L0| / |L0|, about the origin (P = 0 so also about the centre of mass)
    evals_per_step: float
    seconds_per_step: float  # fastest block


class _Tracker:
    """One integrator on its own Context, with its running error figures."""

    def __init__(self, scene, integrator, platform, evals_per_step, name, backend):
        self.ig, self.name, self.evals, self.backend = integrator, name, evals_per_step, backend
        self.ctx = scene.context(integrator, platform)
        self.masses = scene.masses()
        self.n_dof = degrees_of_freedom(scene.system)
        self.e0, self.p0, self.l0 = self._measure()
        self.worst = self.dp = self.dl = 0.0

    def _measure(self):
        st = self.ctx.getState(getEnergy=True, getPositions=True, getVelocities=True)
        e = (st.getPotentialEnergy() + st.getKineticEnergy()).value_in_unit(unit.kilojoule_per_mole)
        return e, linear_momentum(st, masses=self.masses), angular_momentum(st, about="origin", masses=self.masses)

    def record(self):
        e, p, l = self._measure()
        self.worst = max(self.worst, abs(e - self.e0) / self.n_dof)
        self.dp = max(self.dp, float(np.linalg.norm(p - self.p0)))
        self.dl = max(self.dl, float(np.linalg.norm(l - self.l0) / np.linalg.norm(self.l0)))


def run_demo(methods=("verlet", "yoshida-4"), n_waters: int = 64, steps: int = 2000, step_fs: float = 2.0,
             platform: str = "Reference", chunk: int = 100, backend: str = "auto", out=print):
    """Run the demo and print its table; returns the rows."""
    mm.Platform.getPlatformByName(platform)  # a clear OpenMMException for an unknown platform, before any work
    scene = water_cluster(n_waters)
    h = step_fs * unit.femtoseconds
    chunk = max(1, min(chunk, steps))
    out(f"Scene: {scene.description}; {steps} steps of {step_fs:g} fs on {platform}.")
    out("OpenMM's VerletIntegrator is leapfrog: its State velocities lag half a step, so x_n x v_(n-1/2) is")
    out("not an invariant for it; our integrators report synchronous (x_n, v_n).\n")
    trackers = [_Tracker(scene, mm.VerletIntegrator(h), platform, 1.0, "OpenMM VerletIntegrator", "OpenMM")]
    for name in methods:
        ig = SymplecticIntegrator(h, name, system=scene.system, backend=backend)
        trackers.append(_Tracker(scene, ig, platform, ig.program_info.force_evals, f"symprk {ig.method_name}",
                                 ig.backend))
    by_name = {tr.name: tr for tr in trackers}
    timings = interleaved({tr.name: tr.ig.step for tr in trackers}, chunk, rounds=max(1, steps // chunk),
                          after=lambda name: by_name[name].record())
    rows = [DemoRow(tr.name, tr.backend, tr.worst, tr.dp, tr.dl, tr.evals, timings[tr.name].best) for tr in trackers]
    base = rows[0].seconds_per_step
    out(f"{'integrator':28s} {'backend':8s} {'max|dE|/dof':>12s} {'|dP|':>10s} {'|dL|/|L|':>10s} {'f/step':>6s} "
        f"{'time/Verlet':>11s}")
    for r in rows:
        out(f"{r.name:28s} {r.backend:8s} {r.energy_error:12.3e} {r.dP:10.2e} {r.dL_rel:10.2e} "
            f"{r.evals_per_step:6.0f} {r.seconds_per_step / base:11.2f}")
    out("\n|dE| in kJ/mol per degree of freedom; |dP| in Da nm/ps; time per step relative to OpenMM's "
        "VerletIntegrator, each the fastest of its blocks of steps, the integrators taking turns block by block.")
    return rows
