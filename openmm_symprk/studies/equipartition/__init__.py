"""Equipartition of rigid water between translation and rotation, per integrator and step size.

``symprk equipartition`` (or :func:`run_study`): NVE runs of a rigid-water box from independent Langevin-
equilibrated replica states, for each method and step, with T_rot - T_trans, T_trans, potential energy per
molecule and energy drift, each with an error bar; the cheapest configuration that agrees with Verlet at
0.5 fs; a chart.  See docs/equipartition.md.
"""
from . import presets
from .study import load_runs, run_study

__all__ = ["presets", "run_study", "load_runs"]
