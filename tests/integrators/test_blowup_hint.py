"""A blow-up of a System whose bonds to hydrogen are not constrained, at a step of 2 fs or more, names the missing
constraints (SimulationBlowUpError, both backends); a System that constrains them gets no such words."""
import warnings

import openmm as mm
import openmm.unit as unit
import pytest

from openmm_symprk import SimulationBlowUpError, SymplecticIntegrator, plugin
from openmm_symprk.systems.scenes import water_cluster

BACKENDS = ["custom", pytest.param("native", marks=pytest.mark.skipif(
    not plugin.available(), reason=f"native plugin unavailable: {plugin.unavailable_reason()}"))]


def _blow_up(scene, step_fs, backend):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ig = SymplecticIntegrator(step_fs * unit.femtoseconds, "verlet", system=scene.system, backend=backend)
    ctx = mm.Context(scene.system, ig, mm.Platform.getPlatformByName("Reference"))
    ctx.setPositions(scene.positions)
    ctx.setVelocities(scene.velocities)
    with pytest.raises(SimulationBlowUpError) as info:
        ig.step(2000)
    return str(info.value)


@pytest.mark.parametrize("backend", BACKENDS)
def test_a_blow_up_without_hbonds_at_4_fs_names_the_missing_constraints(backend):
    msg = _blow_up(water_cluster(8, rigid=False), 4, backend)
    assert "The System has 16 bond(s) to hydrogen that are not constrained" in msg
    assert "at 4 fs" in msg and "constraints=app.HBonds" in msg


@pytest.mark.parametrize("backend", BACKENDS)
def test_a_blow_up_with_the_hydrogens_constrained_does_not_blame_them(backend):
    msg = _blow_up(water_cluster(8), 14, backend)
    assert "blew up" in msg and "hydrogen" not in msg and "HBonds" not in msg
