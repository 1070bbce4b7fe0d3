"""Measured convergence order of a compiled integrator on an OpenMM scene.

The order comes from successive step refinements (:func:`openmm_symprk.methods.orders.observed_orders`), so
no reference solution is needed; y is the concatenated positions and velocities at the final time.
"""
from __future__ import annotations

import numpy as np
import openmm.unit as unit

from ..methods.orders import observed_orders


def final_state(scene, make_integrator, n_steps: int, T_ps: float, platform="Reference", properties=None):
    """Positions and velocities after ``n_steps`` steps of size T/n from the scene's initial state."""
    ig = make_integrator(T_ps / n_steps)
    ctx = scene.context(ig, platform, properties)
    ig.step(n_steps)
    st = ctx.getState(getPositions=True, getVelocities=True)
    x = st.getPositions(asNumpy=True).value_in_unit(unit.nanometer)
    v = st.getVelocities(asNumpy=True).value_in_unit(unit.nanometer / unit.picosecond)
    del ctx
    return np.concatenate([x.ravel(), v.ravel()])


def measure_order(scene, make_integrator, T_ps: float, steps=(10, 20, 40, 80), platform="Reference"):
    """(orders, differences): one order estimate per consecutive triple of step counts.

    ``make_integrator(h_ps)`` returns a fresh integrator at step size h."""
    return observed_orders([final_state(scene, make_integrator, n, T_ps, platform) for n in steps], steps)
