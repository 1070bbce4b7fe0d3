"""OpenMM's TestCustomIntegrator::testConstraints set-up (8 charged particles in a constrained chain, 2 fs, constraint
tolerance 1e-5, 1000 steps; constraint lengths within 2e-5 and total energy within 1 % of step 1) with the package's
integrators on OpenCL (PoCL here).  pefrl on the CustomIntegrator backend in *single* precision misses the energy
bound (docs/openmm_notes.md, "Single precision and small drifts"): its RATTLE velocity correction (x - x_u)/(c h)
divides single-precision position round-off by pefrl's smallest drift, |c| h = 0.066 x 2 fs.  The native backend
(displacements in their own buffer) and mixed precision meet it; this file checks both and prints all four figures
(``pytest -s``)."""
import numpy as np
import openmm as mm
import pytest

from openmm_symprk import SymplecticIntegrator, plugin
from helpers import COMMON


def _opencl():
    try:
        mm.Platform.getPlatformByName(COMMON)
        return True
    except mm.OpenMMException:
        return False


pytestmark = [pytest.mark.skipif(not _opencl(), reason=f"no {COMMON} platform"),
              pytest.mark.filterwarnings("ignore::UserWarning")]


def constraints_chain(method, backend, precision):
    n = 8
    system, nb = mm.System(), mm.NonbondedForce()
    for i in range(n):
        system.addParticle(5.0 if i % 2 == 0 else 10.0)
        nb.addParticle(0.2 if i % 2 == 0 else -0.2, 0.5, 5.0)
    for i in range(n - 1):
        system.addConstraint(i, i + 1, 1.0)
    system.addForce(nb)
    x = np.array([[i // 2, (i + 1) // 2, 0] for i in range(n)], dtype=float)
    v = np.random.default_rng(0).random((n, 3)) - 0.5
    ig = SymplecticIntegrator(0.002, method, system=system, backend=backend)
    ig.setConstraintTolerance(1e-5)
    ctx = mm.Context(system, ig, mm.Platform.getPlatformByName(COMMON), {"Precision": precision})
    ctx.setPositions(x)
    ctx.setVelocities(v)
    worst_d = worst_e = 0.0
    e0 = None
    for i in range(1000):
        st = ctx.getState(getPositions=True, getEnergy=True)
        X = st.getPositions(asNumpy=True)._value
        worst_d = max(worst_d, float(np.abs(np.linalg.norm(X[1:] - X[:-1], axis=1) - 1).max()))
        e = (st.getKineticEnergy() + st.getPotentialEnergy())._value
        if i == 1:
            e0 = e
        elif i > 1:
            worst_e = max(worst_e, abs(e - e0) / max(abs(e0), abs(e), 1.0))
        ig.step(1)
    print(f"{method} {backend} OpenCL {precision}: max |d - 1| {worst_d:.2e} nm, max relative energy change "
          f"{worst_e:.2e}")
    return worst_d, worst_e


@pytest.mark.parametrize("backend, precision", [
    pytest.param("native", "single", marks=pytest.mark.skipif(not plugin.available(), reason="no native plugin")),
    ("custom", "mixed")])
def test_pefrl_meets_openmms_constraint_test(backend, precision):
    worst_d, worst_e = constraints_chain("pefrl", backend, precision)
    assert worst_d < 2e-5 and worst_e < 0.01


def test_pefrl_custom_single_is_the_documented_exception():
    """The known limitation, measured: custom pefrl in single precision drifts in energy far more than the native
    backend on the same platform (1.6e-2 against 9e-6 when written), while its constraints hold."""
    worst_d, worst_e = constraints_chain("pefrl", "custom", "single")
    assert worst_d < 2e-5 and worst_e > 1e-3
