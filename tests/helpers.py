"""Small float64 measurements shared by the OpenMM tests (built on openmm_symprk.conservation)."""
import os
import re

import numpy as np
import openmm as mm
import openmm.app as app
import pytest
import openmm.unit as unit

from openmm_symprk.conservation import angular_momentum, linear_momentum
from openmm_symprk.methods.orders import observed_orders

#: An issue number of the project ("issue 26", "issues 33 and 36", "--preset issue26"): the project's history, which
#: users do not know, and which no ``--help`` (tests/test_architecture.py) and no heading of the docs
#: (tests/test_docs.py) names.
ISSUE_NUMBER = re.compile(r"\bissues?[\s#_-]*\d", re.I)

#: The platform that runs the plugin's Common kernel in the tests: OpenCL (PoCL in CI), or the one named by
#: SYMPRK_TEST_COMMON_PLATFORM (CUDA on a machine with an NVIDIA GPU), so the same assertions check that kernel there.
COMMON = os.environ.get("SYMPRK_TEST_COMMON_PLATFORM", "OpenCL")


class Counter:
    """A callable for openmm.PythonForce that contributes nothing but counts its evaluations."""

    def __init__(self):
        self.n = 0

    def __call__(self, state):
        self.n += 1
        return 0.0, np.zeros((state.getPositions(asNumpy=True).shape[0], 3))


def counted(scene):
    """A copy of the scene's System with a counting PythonForce added, and its Counter."""
    import copy

    import openmm as mm

    system = copy.deepcopy(scene.system)
    counter = Counter()
    system.addForce(mm.PythonForce(counter))
    return system, counter


def reference_context(system, integrator, scene):
    """A Reference Context of ``system`` (e.g. the scene's with a Counter) at the scene's initial state."""
    import openmm as mm

    ctx = mm.Context(system, integrator, mm.Platform.getPlatformByName("Reference"))
    ctx.setPositions(scene.positions)
    ctx.setVelocities(scene.velocities)
    return ctx


def evaluations(integrator, counters, steps: int) -> tuple:
    """The evaluations each Counter of ``counters`` counts in ``steps`` steps of ``integrator``."""
    for c in counters:
        c.n = 0
    integrator.step(steps)
    return tuple(c.n for c in counters)


def momenta(ctx, masses):
    """(P, L about the origin, sum m|v|) in float64."""
    state = ctx.getState(getPositions=True, getVelocities=True)
    v = state.getVelocities(asNumpy=True).value_in_unit(unit.nanometer / unit.picosecond)
    return (linear_momentum(state, masses=masses), angular_momentum(state, about="origin", masses=masses),
            float(np.sum(masses[:, None] * np.abs(v))))


def drift_after(ctx, integrator, masses, steps):
    """(|dP| / sum m|v|, |dL|/|L|) after ``steps`` steps."""
    p0, l0, scale = momenta(ctx, masses)
    integrator.step(steps)
    p1, l1, _ = momenta(ctx, masses)
    return float(np.linalg.norm(p1 - p0) / scale), float(np.linalg.norm(l1 - l0) / np.linalg.norm(l0))


def stiff_diatomic():
    """Two unit masses on a stiff harmonic bond (omega = sqrt(2k/m) ~ 447/ps): steps beyond a method's
    stability limit make it blow up within a few dozen steps."""
    import openmm as mm

    system = mm.System()
    system.addParticle(1.0)
    system.addParticle(1.0)
    bond = mm.HarmonicBondForce()
    bond.addBond(0, 1, 0.1, 1.0e5)
    system.addForce(bond)
    return system


def final_state(scene, make_integrator, n_steps: int, T_ps: float, platform="Reference"):
    """Positions and velocities after ``n_steps`` steps of size T/n from the scene's initial state."""
    ig = make_integrator(T_ps / n_steps)
    ctx = scene.context(ig, platform)
    ig.step(n_steps)
    st = ctx.getState(getPositions=True, getVelocities=True)
    x = st.getPositions(asNumpy=True).value_in_unit(unit.nanometer)
    v = st.getVelocities(asNumpy=True).value_in_unit(unit.nanometer / unit.picosecond)
    del ctx
    return np.concatenate([x.ravel(), v.ravel()])


def measure_order(scene, make_integrator, T_ps: float, steps=(10, 20, 40, 80), platform="Reference"):
    """Measured convergence order of a compiled integrator on an OpenMM scene: (orders, differences), one order
    estimate per consecutive triple of step counts, from successive refinements
    (:func:`openmm_symprk.methods.orders.observed_orders`: no reference solution needed).  ``make_integrator(h_ps)``
    returns a fresh integrator at step size h."""
    return observed_orders([final_state(scene, make_integrator, n, T_ps, platform) for n in steps], steps)


def tip4p_waters(n: int, rigid: bool):
    """(system, positions) of ``n`` TIP4P-Ew waters in vacuum, a massless virtual site each (not minimised)."""
    from openmm_symprk.systems.scenes import water_cluster

    base = water_cluster(n, minimize=False)
    mod = app.Modeller(base.topology, base.positions * unit.nanometer)
    ff = app.ForceField("tip4pew.xml")
    mod.addExtraParticles(ff)
    system = ff.createSystem(mod.topology, nonbondedMethod=app.NoCutoff, constraints=None, rigidWater=rigid,
                             removeCMMotion=False)
    return system, mod.positions


def tip4p_cluster(n: int = 8, iterations: int = 100, as_numpy: bool = False):
    """(system, positions, velocities) of ``n`` rigid TIP4P-Ew waters in vacuum (a massless virtual site each),
    minimised on Reference (``iterations`` at most), velocities at 100 K with the constraints applied."""
    system, positions = tip4p_waters(n, rigid=True)
    ctx = mm.Context(system, mm.VerletIntegrator(0.001), mm.Platform.getPlatformByName("Reference"))
    ctx.setPositions(positions)
    ctx.applyConstraints(1e-10)
    mm.LocalEnergyMinimizer.minimize(ctx, 1.0, iterations)
    ctx.setVelocitiesToTemperature(100, 1)
    ctx.applyVelocityConstraints(1e-10)
    st = ctx.getState(getPositions=True, getVelocities=True)
    return system, st.getPositions(asNumpy=as_numpy), st.getVelocities(asNumpy=as_numpy)


def virtual_site_error(system, x) -> float:
    """Largest distance (nm) between a virtual site's position in ``x`` and the one its rule gives."""
    err = 0.0
    for i in range(system.getNumParticles()):
        if system.isVirtualSite(i):
            vs = system.getVirtualSite(i)
            expect = sum(vs.getWeight(k) * x[vs.getParticle(k)] for k in range(vs.getNumParticles()))
            err = max(err, float(np.abs(x[i] - expect).max()))
    return err


def native_skip_reason():
    """Why the native backend cannot run here (its plugin did not build or load), or None."""
    from openmm_symprk import plugin

    return None if plugin.available() else f"native backend unavailable: {plugin.unavailable_reason()}"


#: Both backends as pytest parameters; native is skipped only where its plugin is missing, so that a native
#: regression fails instead of hiding behind a probe.
BACKENDS = ["custom", pytest.param("native", marks=pytest.mark.skipif(
    native_skip_reason() is not None, reason=str(native_skip_reason())))]
#: The same, for the long runs of a water box (10-25 s each): the custom backend's is marked slow (.ci/run runs it
#: after the suite), the native one stays in the suite.
BACKENDS_LONG = [pytest.param("custom", marks=pytest.mark.slow), BACKENDS[1]]


def context(system, integrator, x, v, platform="Reference", properties=None):
    """A Context on ``platform`` with positions ``x`` and velocities ``v``."""
    import openmm as mm

    ctx = mm.Context(system, integrator, mm.Platform.getPlatformByName(platform), properties or {})
    ctx.setPositions(x)
    ctx.setVelocities(v)
    return ctx


def positions_velocities(ctx):
    """(positions nm, velocities nm/ps) of a Context as float64 arrays."""
    st = ctx.getState(getPositions=True, getVelocities=True)
    return (np.asarray(st.getPositions(asNumpy=True).value_in_unit(unit.nanometer)),
            np.asarray(st.getVelocities(asNumpy=True).value_in_unit(unit.nanometer / unit.picosecond)))
