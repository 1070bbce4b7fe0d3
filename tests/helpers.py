"""Small float64 measurements shared by the OpenMM tests."""
import numpy as np
import openmm.unit as unit


def momenta(ctx, masses):
    st = ctx.getState(getPositions=True, getVelocities=True)
    x = st.getPositions(asNumpy=True).value_in_unit(unit.nanometer)
    v = st.getVelocities(asNumpy=True).value_in_unit(unit.nanometer / unit.picosecond)
    m = masses[:, None]
    return (m * v).sum(0), (m * np.cross(x, v)).sum(0), float(np.sum(m * np.abs(v)))


def drift_after(ctx, integrator, masses, steps):
    """(|dP| / sum m|v|, |dL|/|L|) after ``steps`` steps."""
    p0, l0, scale = momenta(ctx, masses)
    integrator.step(steps)
    p1, l1, _ = momenta(ctx, masses)
    return float(np.linalg.norm(p1 - p0) / scale), float(np.linalg.norm(l1 - l0) / np.linalg.norm(l0))
