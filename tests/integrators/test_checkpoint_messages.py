"""A checkpoint refused for a mismatch says what differs and what to do, on both backends: the native backend's
loadCheckpoint raises OpenMMException, the custom backend's next step CheckpointMismatchError.  A change of ensemble
points to saveState/loadState; a checkpoint of one of OpenMM's integrators gets no backend='custom' hint."""
import re
import warnings

import openmm as mm
import pytest

from openmm_symprk import CheckpointMismatchError, SymplecticIntegrator, plugin

BACKENDS = ["custom", pytest.param("native", marks=pytest.mark.skipif(
    not plugin.available(), reason=f"native plugin unavailable: {plugin.unavailable_reason()}"))]


def _checkpoint(scene, integrator):
    ctx = scene.context(integrator)
    integrator.step(3)
    return ctx.createCheckpoint()


def _refusal(scene, backend, checkpoint, method="verlet", **options):
    """The message with which an integrator of ``options`` refuses ``checkpoint``."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ig = SymplecticIntegrator(0.001, method, system=scene.system, backend=backend, **options)
    ctx = scene.context(ig)
    error = mm.OpenMMException if backend == "native" else CheckpointMismatchError
    with pytest.raises(error) as info:
        ctx.loadCheckpoint(checkpoint)
        ig.step(1)
    return str(info.value)


def _ours(scene, backend, method="verlet", **options):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return _checkpoint(scene, SymplecticIntegrator(0.001, method, system=scene.system, backend=backend, **options))


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("saved, loaded", [({}, {"temperature": 300}), ({"temperature": 300}, {})])
def test_a_change_of_ensemble_names_it_and_points_to_save_and_load_state(water8, backend, saved, loaded):
    msg = _refusal(water8, backend, _ours(water8, backend, **saved), **loaded)
    was, now = ("NVT", "NVE") if saved else ("NVE", "NVT")
    assert re.search(f"what differs: the ensemble \\(the checkpoint's run was {was}.*this integrator runs {now}\\)", msg)
    assert "Simulation.saveState" in msg and "Simulation.loadState" in msg, msg


@pytest.mark.parametrize("backend", BACKENDS)
def test_another_method_is_named(water8, backend):
    msg = _refusal(water8, backend, _ours(water8, backend), method="omelyan-2")
    assert "what differs: the method (the checkpoint's run used 'verlet'; this integrator runs 'omelyan-2')" in msg


@pytest.mark.parametrize("backend", BACKENDS)
def test_exact_momentum_is_named(water8, backend):
    msg = _refusal(water8, backend, _ours(water8, backend), exact_momentum=True)
    assert "what differs: exact_momentum (the checkpoint's run had it off; this integrator has it on)" in msg


@pytest.mark.parametrize("backend", BACKENDS)
def test_another_thermostat_interval_is_named(water8, backend):
    msg = _refusal(water8, backend, _ours(water8, backend, temperature=300), temperature=300, thermostat_interval=2)
    if backend == "custom":  # its programs are compiled again to find which
        assert "what differs: thermostat_interval (the checkpoint's run had 1; this integrator has 2)" in msg
    else:  # the plugin's checkpoint holds a hash of the settings: it names the candidates
        assert "what differs: the thermostat's settings other than its temperature (collision_time, " \
               "thermostat_interval, thermostat_position)" in msg


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("openmm", ["LangevinMiddleIntegrator", "VerletIntegrator"])
def test_a_checkpoint_of_an_openmm_integrator_gets_no_backend_hint(water8, backend, openmm):
    other = mm.LangevinMiddleIntegrator(300, 1, 0.001) if openmm == "LangevinMiddleIntegrator" else \
        mm.VerletIntegrator(0.001)
    msg = _refusal(water8, backend, _checkpoint(water8, other))
    assert "backend=" not in msg, msg
    assert "another integrator (OpenMM's VerletIntegrator, LangevinMiddleIntegrator and the like)" in msg
    assert "Simulation.saveState" in msg and "Simulation.loadState" in msg


@pytest.mark.skipif(not plugin.available(), reason="native plugin unavailable")
def test_checkpoints_across_backends_still_name_the_backend(water8):
    assert "backend='custom'" in _refusal(water8, "native", _ours(water8, "custom"))
    custom = SymplecticIntegrator(0.001, "verlet", system=water8.system, backend="custom")
    ctx = water8.context(custom)
    try:
        ctx.loadCheckpoint(_ours(water8, "native"))
    except mm.OpenMMException:
        return  # OpenMM may refuse the stream itself
    with pytest.raises(CheckpointMismatchError, match="written by the native backend.*backend='native'"):
        custom.step(1)


def test_naming_what_differs_warns_about_nothing():
    """Working out what a refused checkpoint's run had compiles candidate programs; that gives no warning of its own
    (a PlacementWarning per candidate method would both flood the user and use up the warning a real integrator of
    that method is owed)."""
    import warnings

    import openmm as mm

    from openmm_symprk import SymplecticIntegrator
    from openmm_symprk.integrators.mismatch import mismatch_message
    from openmm_symprk.systems.scenes import water_cluster

    from openmm_symprk.systems.checks import warn_once

    scene = water_cluster(8)
    ig = SymplecticIntegrator(0.002, "verlet", system=scene.system, backend="custom", temperature=300,
                              thermostat_position="middle")
    warn_once.reset()
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        text = mismatch_message("X", ig.resolved, ig.options, ig.thermostat, 12345.0, ig.program_info.signature,
                                scene.system)
    assert "another integrator program" in text
