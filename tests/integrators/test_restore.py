"""An integrator read back from XML: the metadata of its program, the method resolved and compiled again from it and
checked against the program's signature, user methods included (integrators.metadata, integrators.restore)."""
import json

import numpy as np
import openmm as mm
import openmm.unit as unit
import pytest

from openmm_symprk import PRKIntegrator, PRKTableau, Splitting, SymplecticIntegrator, catalogue
from openmm_symprk.integrators import CustomSymplecticIntegrator, IntegratorOptions, deserialize
from openmm_symprk.integrators.metadata import META_PREFIX, read_metadata

USER_SPLITTING = Splitting([("kick", "1/3"), ("drift", "1/2"), ("kick", "1/3"), ("drift", "1/2"), ("kick", "1/3")])


def _lobatto_like():
    """A user copy of the catalogue's Lobatto IIIA-IIIB pair (implicit), under another name."""
    t = catalogue["lobatto-iiia-iiib-3"].tableau()
    return PRKTableau(t.A, t.b, t.A_hat, t.b_hat, name="my lobatto")


def _rk4():
    t = catalogue["rk4"].tableau()
    return PRKTableau(t.A, t.b, t.A_hat, t.b_hat, name="my rk4")


def _positions(ctx):
    return ctx.getState(getPositions=True).getPositions(asNumpy=True).value_in_unit(unit.nanometer)


def _with_metadata(xml: str, change) -> str:
    """``xml`` with its metadata replaced by ``change(metadata)``."""
    start = xml.index(META_PREFIX) + len(META_PREFIX)
    end = xml.index('"', start)
    meta = json.loads(bytes.fromhex(xml[start:end]).decode())
    change(meta)
    return xml[:start] + json.dumps(meta, separators=(",", ":")).encode().hex() + xml[end:]


@pytest.mark.parametrize("build", [
    lambda s: PRKIntegrator(0.0005, USER_SPLITTING, system=s.system, name="thirds"),
    lambda s: PRKIntegrator(0.0005, _lobatto_like(), system=s.system, tolerance=1e-10, max_iterations=25),
    lambda s: PRKIntegrator(0.0005, _rk4(), system=s.system, allow_nonsymplectic=True, exact_momentum=True),
    lambda s: PRKIntegrator(0.0005, "pefrl", system=s.system, name="mine", constraints=True),
    lambda s: CustomSymplecticIntegrator(0.0005, "yoshida-4", constraints=False, max_speed=50.0),
    lambda s: CustomSymplecticIntegrator(0.0005, "gauss-2", system=s.system, tolerance=1e-9),
], ids=["user-splitting", "user-implicit", "user-explicit", "catalogue-renamed", "catalogue-options",
        "catalogue-implicit"])
def test_restored_from_xml_is_the_same_integrator(build, morse):
    ig = build(morse)
    back = deserialize(mm.XmlSerializer.serialize(ig))
    assert type(back) is type(ig) and back.method_name == ig.method_name
    assert back.resolved == ig.resolved  # the method, resolved again from what the program stored
    assert (back.program_info.signature, back.program_info.rattle) == (ig.program_info.signature,
                                                                       ig.program_info.rattle)
    assert back.program_info.notes == (*ig.program_info.notes, "restored from XML")
    assert back.options == ig.options  # every option, the non-default ones included
    assert ig.describe().splitlines()[1:3] == back.describe().splitlines()[1:3]
    a, b = morse.context(ig), morse.context(back)
    ig.step(20)
    back.step(20)
    np.testing.assert_array_equal(_positions(a), _positions(b))


def test_multiple_time_stepping_with_a_user_inner_method(water8):
    from openmm_symprk.systems.forcegroups import split_forces

    system = mm.XmlSerializer.deserialize(mm.XmlSerializer.serialize(water8.system))
    groups = split_forces(system, slow="nonbonded")
    for inner in (USER_SPLITTING, None):
        outer = "omelyan-2" if inner is not None else USER_SPLITTING
        ig = PRKIntegrator(0.001, outer, system=system, groups=groups, inner_method=inner)
        back = deserialize(mm.XmlSerializer.serialize(ig))
        assert back.resolved == ig.resolved and back.resolved.is_mts
        assert back.program_info.signature == ig.program_info.signature


def test_the_metadata_of_default_options_has_no_new_keys():
    """Options at their defaults are not written where the metadata of earlier versions did not have them, so the
    programs of those options keep their XML (tests/integrators/test_golden_programs.py); the others are."""
    plain = read_metadata(SymplecticIntegrator(0.001, "verlet", backend="custom"))
    assert list(plain) == ["class", "method", "catalogue", "options", "system"]
    assert list(plain["options"]) == ["exact_momentum", "check_finite", "max_speed", "groups", "inner_method"]
    given = read_metadata(SymplecticIntegrator(0.001, "gauss-2", backend="custom", constraints=False, tolerance=1e-8,
                                               max_iterations=9))
    assert {k: given["options"][k] for k in ("constraints", "tolerance", "max_iterations")} == {
        "constraints": False, "tolerance": 1e-8, "max_iterations": 9}
    user = read_metadata(PRKIntegrator(0.001, USER_SPLITTING))
    assert user["catalogue"] is None and user["description"]["splitting"][0] == ["kick", "1/3"]


def test_a_program_that_is_not_what_its_metadata_compiles_to_is_refused():
    ig = SymplecticIntegrator(0.001, "yoshida-4", backend="custom")
    xml = mm.XmlSerializer.serialize(ig)
    edited = _with_metadata(xml, lambda meta: meta["options"].update(max_speed=30.0))
    with pytest.raises(ValueError, match=r"CustomSymplecticIntegrator\(yoshida-4\) program is not the one its "
                                         r"metadata compiles to \(its signature \d+, recompiled \d+\)"):
        deserialize(edited)
    old_user = _with_metadata(mm.XmlSerializer.serialize(PRKIntegrator(0.001, USER_SPLITTING)),
                              lambda meta: meta.pop("description"))
    with pytest.raises(ValueError, match="'user splitting' does not describe its method"):
        deserialize(old_user)


def test_options_are_built_once_and_frozen(water8):
    ig = SymplecticIntegrator(0.002, "verlet", system=water8.system, backend="custom", max_speed=40 * unit.nanometer
                              / unit.picosecond, groups=[[0, 1]], temperature=300)
    opts = ig.options
    assert isinstance(opts, IntegratorOptions) and ig.program_info.method is ig.resolved
    assert (opts.step_size, opts.max_speed, opts.groups, opts.system.n_particles) == (0.002, 40.0, ((0, 1),), 24)
    assert (opts.check_finite, opts.exact_momentum, opts.constraints, opts.tolerance) == (True, False, None, 1e-12)
    with pytest.raises(AttributeError):
        opts.max_speed = 1.0
    assert IntegratorOptions.build("X", 0.002, water8.system, max_speed=40.0, groups=[(0, 1)]) == opts
    # the thermostat's settings live in one holder, which setTemperature replaces: no construction-time copy
    assert not hasattr(opts, "thermostat") and ig.thermostat.temperature == 300.0
    ig.setTemperature(310)
    assert ig.thermostat.temperature == 310.0 and deserialize(mm.XmlSerializer.serialize(ig)).thermostat == ig.thermostat


_RESTORE_AND_DROP = """
import gc, sys
import openmm as mm, openmm.app as app
from openmm_symprk import SymplecticIntegrator, restore
from openmm_symprk.systems.scenes import water_cluster
scene = water_cluster(8)
ig = SymplecticIntegrator(0.002, "verlet", system=scene.system, backend=sys.argv[1])
original = mm.XmlSerializer.deserialize(mm.XmlSerializer.serialize(ig))
kept = restore(mm.XmlSerializer.deserialize(mm.XmlSerializer.serialize(ig)))
restore(original)  # the result dropped: `original` must stay a valid integrator
del ig
gc.collect()
sim = app.Simulation(scene.topology, scene.system, original, mm.Platform.getPlatformByName("Reference"))
sim.context.setPositions(scene.positions)
sim.step(5)
other = mm.XmlSerializer.deserialize(mm.XmlSerializer.serialize(kept))
wrapper = restore(other)
del other  # and the other way round: the wrapper keeps the integrator it wraps alive
gc.collect()
ctx = mm.Context(scene.system, wrapper, mm.Platform.getPlatformByName("Reference"))
ctx.setPositions(scene.positions)
wrapper.step(5)
print("stepped", sim.currentStep, wrapper.steps_taken)
"""


@pytest.mark.parametrize("backend", ["custom", pytest.param("native", marks=pytest.mark.skipif(
    not __import__("openmm_symprk").plugin.available(), reason="native plugin unavailable"))])
def test_restore_leaves_the_integrator_it_wraps_valid(backend):
    """restore(x) whose result is dropped, then x used in a Simulation (README's restore(XmlSerializer.deserialize(
    xml)) idiom, or restore(x) taken to change x in place): before the fix the result took over x's C++ object and
    deleted it, and the native backend's next use of x killed the interpreter (exit 139).  Run in a subprocess, so
    that a crash fails the test instead of ending the session."""
    import subprocess
    import sys

    done = subprocess.run([sys.executable, "-W", "ignore", "-c", _RESTORE_AND_DROP, backend], capture_output=True,
                          text=True, timeout=300)
    assert done.returncode == 0, (done.returncode, done.stderr[-2000:])
    assert done.stdout.split() == ["stepped", "5", "5"]
