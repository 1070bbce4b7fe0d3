"""The thermostat at the edges OpenMM's own thermostat tests and unusual input reach (issue 27): a reinitialized
Context, copies of a used integrator, clusters far from the origin, systems without peculiar kinetic energy, linear
molecules, checkpoints with another temperature.  Each test failed before its fix."""
import copy
import pickle
import warnings

import numpy as np
import openmm as mm
import openmm.unit as unit
import pytest

from openmm_symprk import SymplecticIntegrator, plugin
from openmm_symprk.integrators import deserialize
from openmm_symprk.systems.scenes import water_cluster

REF = "Reference"
pytestmark = pytest.mark.filterwarnings("ignore::openmm_symprk.systems.checks.ConservationWarning")


def _native_reason():
    if not plugin.available():
        return f"native backend unavailable: {plugin.unavailable_reason()}"
    return None


BACKENDS = ["custom", pytest.param("native", marks=pytest.mark.skipif(_native_reason() is not None,
                                                                        reason=str(_native_reason())))]


def context(system, ig, x, v, platform=REF):
    ctx = mm.Context(system, ig, mm.Platform.getPlatformByName(platform))
    ctx.setPositions(x)
    ctx.setVelocities(v)
    return ctx


def velocities(ctx):
    return np.asarray(ctx.getState(getVelocities=True).getVelocities(asNumpy=True)
                      .value_in_unit(unit.nanometer / unit.picosecond))


@pytest.fixture(scope="module")
def cluster():
    return water_cluster(8)


# -- 1: a reinitialized Context is thermostatted from its first step --------------------------------------------------
@pytest.mark.parametrize("backend", BACKENDS)
def test_reinitialize_thermostats_from_the_first_step(backend, cluster):
    """OpenMM's testRandomSeed, ported: after Context.reinitialize() and the same positions and velocities, the
    same integrator (same seed) repeats its first run; before the fix the whole next step(n) ran without the
    thermostat (no heat exchanged)."""
    ig = SymplecticIntegrator(0.002, "verlet", system=cluster.system, backend=backend, temperature=300,
                              collision_time=0.02, random_seed=1)
    ctx = context(cluster.system, ig, cluster.positions, cluster.velocities)
    ig.step(20)
    first, heat_first = velocities(ctx), ig.computeHeatBathEnergy()
    ctx.reinitialize()
    ctx.setPositions(cluster.positions)
    ctx.setVelocities(cluster.velocities)
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        ig.step(1)
        heat_after_one = ig.computeHeatBathEnergy()
        ig.step(19)
    assert heat_after_one != heat_first  # the first step after reinitialize ran an event
    assert velocities(ctx).tobytes() == first.tobytes()  # ... and the run repeats the first one
    # a Context reinitialized without its state starts a new run: the heat-bath energy from 0, on both backends
    assert ig.computeHeatBathEnergy() == heat_first


# -- 4: copies of a used integrator carry no run-time state -----------------------------------------------------------
@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("how", ["xml", "pickle", "deepcopy"])
def test_copy_of_a_used_integrator_runs_as_a_fresh_one(backend, cluster, how):
    def make():
        return SymplecticIntegrator(0.002, "omelyan-2", system=cluster.system, backend=backend, temperature=320,
                                    collision_time=0.05, random_seed=21)

    used = make()
    ctx = context(cluster.system, used, cluster.positions, cluster.velocities)
    used.step(15)
    assert used.computeHeatBathEnergy() != 0 * unit.kilojoule_per_mole
    copied = {"xml": lambda: deserialize(mm.XmlSerializer.serialize(used)),
              "pickle": lambda: pickle.loads(pickle.dumps(used)),
              "deepcopy": lambda: copy.deepcopy(used)}[how]()
    del ctx
    assert copied.computeHeatBathEnergy() == 0 * unit.kilojoule_per_mole
    runs = []
    for integrator in (make(), copied):
        c = context(cluster.system, integrator, cluster.positions, cluster.velocities)
        assert integrator.steps_taken == 0
        integrator.step(12)
        runs.append((velocities(c).tobytes(), integrator.computeHeatBathEnergy(), integrator.steps_taken))
        del c
    assert runs[0] == runs[1]
