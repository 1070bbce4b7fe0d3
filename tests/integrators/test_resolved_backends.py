"""Both backends run the one resolved method (methods.resolved.resolve); the option checks they share."""
import pickle
import struct

import numpy as np
import openmm as mm
import openmm.unit as unit
import pytest

from openmm_symprk import PRKIntegrator, SymplecticIntegrator, catalogue, plugin, resolve
from openmm_symprk.integrators import (CustomSymplecticIntegrator, NativeMethodError, NativeSymplecticIntegrator,
                                       deserialize, restore)
from openmm_symprk.methods import SubstepFlag, SubstepKind

needs_native = pytest.mark.skipif(not plugin.available(),
                                  reason=f"native plugin unavailable: {plugin.unavailable_reason()}")
BACKENDS = ["custom", pytest.param("native", marks=needs_native)]
SPLITTINGS = [m.name for m in catalogue.splittings()]


def _plugin_substeps(ig):
    return [(ig.getSubstepKind(i), ig.getSubstepCoefficient(i), ig.getSubstepForceGroups(i), ig.getSubstepFlags(i))
            for i in range(ig.getNumSubsteps())]


def _resolved_substeps(r):
    return [(int(s.kind), float(s.coefficient), s.group_mask, int(s.flags)) for s in r.substeps]


# -- one enum on both sides of SWIG ---------------------------------------------------------------------------------------
@needs_native
def test_substep_enums_are_the_plugins():
    cls = plugin.swig_module().SymPRKIntegrator
    assert (SubstepKind.KICK, SubstepKind.DRIFT) == (cls.Kick, cls.Drift)
    assert (SubstepFlag.PROJECT_BEFORE, SubstepFlag.FORCES_CACHED) == (cls.ProjectVelocitiesBefore, cls.ForcesCached)
    if not hasattr(cls, "Thermostat"):
        pytest.skip("this build of the plugin has no Thermostat sub-step kind yet (thermostat_position='middle')")
    assert {k.name: int(k) for k in SubstepKind} == {"KICK": cls.Kick, "DRIFT": cls.Drift, "THERMOSTAT": cls.Thermostat}


# -- the plugin is sent the resolved sequence and flags ----------------------------------------------------------------------
@needs_native
@pytest.mark.parametrize("name", SPLITTINGS)
def test_native_runs_the_resolved_sequence(name, water8, morse):
    for scene, constraints in ((water8, True), (morse, False)):
        ig = NativeSymplecticIntegrator(0.001, name, system=scene.system)
        r = resolve(name, constraints=constraints)
        assert ig.resolved == r
        assert _plugin_substeps(ig) == _resolved_substeps(r)
        assert ig.getForceEvaluationsPerStep() == r.force_evals == catalogue[name].force_evals


@needs_native
@pytest.mark.filterwarnings("ignore:.*CustomExternalForce")
def test_native_mts_flags():
    from helpers import stiff_diatomic

    system = stiff_diatomic()
    for f in system.getForces():
        f.setForceGroup(0)
    slow = mm.CustomExternalForce("0.1*x^2")
    for i in range(system.getNumParticles()):
        slow.addParticle(i, [])
    slow.setForceGroup(1)
    system.addForce(slow)
    groups = [(1, 1), (0, 4)]
    ig = NativeSymplecticIntegrator(0.001, "yoshida-4", system=system, groups=groups, inner_method="verlet")
    r = resolve("yoshida-4", constraints=False, groups=groups, inner_method="verlet")
    assert ig.resolved == r and _plugin_substeps(ig) == _resolved_substeps(r)
    assert ig.getForceEvaluationsPerStep() == r.force_evals


@needs_native
def test_plugin_checks_the_flags_it_is_sent():
    cls = plugin.swig_module().SymPRKIntegrator
    K, D, P, C = cls.Kick, cls.Drift, cls.ProjectVelocitiesBefore, cls.ForcesCached
    ig = cls(0.001)  # velocity Verlet, its first kick on cached forces
    assert _plugin_substeps(ig) == [(K, 0.5, -1, C), (D, 1.0, -1, 0), (K, 0.5, -1, 0)]
    assert ig.getForceEvaluationsPerStep() == 1
    for kinds, coefficients, groups, flags, match in [
            ([K, D], [0.5, 1.0], [-1, -1], [P, 0], "is a kick flagged ProjectVelocitiesBefore"),
            ([K, D], [0.5, 1.0], [-1, -1], [0, C], "is a drift flagged ForcesCached"),
            ([K, D], [0.5, 1.0], [-1, -1], [0, 16], "has flags 16"),
            ([K, D], [0.5, 1.0], [-1, -1], [0, cls.LastOfInterval], "is a drift flagged 8; FirstOfInterval and "
                                                                     "LastOfInterval name the step of a thermostat event"),
            ([K, cls.Thermostat], [0.5, 1.0], [-1, -1], [0, C], "thermostat event .* takes -1 and flags of 1"),
            ([K, cls.Thermostat], [0.5, 1.0], [-1, -1], [0, 12], "thermostat event .* flags 12; .* one of 4 .first step of the interval. or 8"),
            ([K, 3], [0.5, 1.0], [-1, -1], [0, 0], "has kind 3; expected 0 .kick., 1 .drift. or 2 .thermostat event."),
            ([K, D], [0.0, 1.0], [-1, -1], [0, 0], "finite non-zero"),
            ([K, D], [0.5, 1.0], [-1, 3], [0, 0], "a drift takes -1"),
            ([K, D], [0.5, 1.0], [-1], [0, 0], "same length")]:
        with pytest.raises(mm.OpenMMException, match=match):
            ig.setSubsteps(kinds, coefficients, groups, flags)


# -- the CustomIntegrator program follows the same flags --------------------------------------------------------------------
@pytest.mark.parametrize("name", SPLITTINGS)
def test_custom_program_projects_where_flagged(name, water8):
    ig = CustomSymplecticIntegrator(0.001, name, system=water8.system)
    r = resolve(name, constraints=True)
    assert ig.resolved == r and ig.program_info.force_evals == r.force_evals
    kinds = [ig.getComputationStep(i)[0] for i in range(ig.getNumComputations())]
    kinds = kinds[kinds.index(mm.CustomIntegrator.BlockEnd) + 1:]  # after the one-time probe
    assert kinds.count(mm.CustomIntegrator.ConstrainVelocities) == 1 + sum(s.project_before for s in r.substeps)
    assert kinds.count(mm.CustomIntegrator.ConstrainPositions) == sum(s.kind == SubstepKind.DRIFT for s in r.substeps)


# -- XML and checkpoints say their format -----------------------------------------------------------------------------------
@needs_native
def test_xml_carries_the_flags_and_refuses_the_old_format(water8):
    ig = NativeSymplecticIntegrator(0.001, "pefrl", system=water8.system)
    xml = mm.XmlSerializer.serialize(ig)
    assert 'version="3"' in xml and xml.count("flags=") == ig.getNumSubsteps()
    back = deserialize(xml)
    assert _plugin_substeps(back) == _plugin_substeps(ig) and back.resolved.substeps == ig.resolved.substeps
    assert back.resolved.order == 4 and back.resolved.name == "pefrl"
    old = xml.replace('version="3"', 'version="1"', 1)
    with pytest.raises(Exception, match="older openmm_symprk .serialization version 1"):
        mm.XmlSerializer.deserialize(old)


@needs_native
@pytest.mark.parametrize("interval", [1, 3])
def test_xml_written_before_the_events_were_substeps_still_loads(water8, interval):
    """Native XML of an ends-placement integrator from before the thermostat's events were sub-steps has a Thermostat
    node and no thermostat Substep: it is read back with the ends placement's two events (the plugin's proxy adds
    them), resolved as the method with thermostat_position="ends", with the same program signature (its checkpoints
    load), and it runs the same trajectory bit for bit."""
    import re

    def make():
        return NativeSymplecticIntegrator(0.002, "omelyan-2", system=water8.system, temperature=300, random_seed=3,
                                          thermostat_interval=interval, thermostat_position="ends")

    ig = make()
    xml = mm.XmlSerializer.serialize(ig)
    old = re.sub(r'\s*<Substep c="\.5" flags="(4|8)" kind="thermostat"/>', "", xml)
    assert old.count('kind="thermostat"') == 0 and xml.count('kind="thermostat"') == 2
    back = deserialize(old)
    assert back.resolved == ig.resolved and back.thermostat == ig.thermostat
    assert back.getProgramSignature() == ig.getProgramSignature()
    runs = []
    for integrator in (ig, back):
        ctx = water8.context(integrator)
        integrator.step(7)
        runs.append((ctx.getState(getVelocities=True).getVelocities(asNumpy=True)._value.tobytes(),
                     integrator.computeHeatBathEnergy()))
        del ctx
    assert runs[0] == runs[1]


@needs_native
def test_checkpoint_of_the_old_format_is_refused(water8):
    ig = NativeSymplecticIntegrator(0.001, "verlet", system=water8.system)
    ctx = water8.context(ig)
    ig.step(2)
    chk = ctx.createCheckpoint()
    magic = struct.pack("<q", 0x53796d50524b0005)
    assert chk.count(magic) == 1  # format 5 (3, the thermostat's block and its run state)
    for old in (2, 3):
        with pytest.raises(Exception, match=f"older openmm_symprk .checkpoint format {old}"):
            ctx.loadCheckpoint(chk.replace(magic, struct.pack("<q", 0x53796d50524b0000 + old)))
    ctx.loadCheckpoint(chk.replace(magic, struct.pack("<q", 0x53796d50524b0004)))  # NVE: format 4 is the same block
    ctx.loadCheckpoint(chk)


@needs_native
def test_checkpoint_of_format_4_still_loads_with_its_thermostat(water8):
    """Format 4 had the heat-bath energy and the random state but not the kinetic energies after the last event nor the
    skipped events (the integrator's block ends the Context's checkpoint, and those are its last 32 bytes): it loads,
    and the run continues as from the format-5 checkpoint, bit for bit."""
    ig = NativeSymplecticIntegrator(0.001, "verlet", system=water8.system, temperature=300, random_seed=9)
    ctx = water8.context(ig)
    ig.step(5)
    chk = ctx.createCheckpoint()
    heat = ig.computeHeatBathEnergy()
    magic = struct.pack("<q", 0x53796d50524b0005)
    tail = struct.pack("<dd", ig.getThermostatKineticEnergy(), ig.getThermostatPeculiarKineticEnergy()) + bytes(16)
    assert chk.count(magic) == 1 and chk.endswith(tail)
    old = chk.replace(magic, struct.pack("<q", 0x53796d50524b0004))[:-32]
    runs = []
    for checkpoint in (chk, old):
        ctx.loadCheckpoint(checkpoint)
        assert ig.computeHeatBathEnergy() == heat
        runs.append(ig.getThermostatKineticEnergy())
        ig.step(5)
        runs.append(ctx.getState(getVelocities=True).getVelocities(asNumpy=True)._value.tobytes())
    assert runs[0] != 0 and runs[2] == 0  # format 4 knows no kinetic energy of the last event
    assert runs[1] == runs[3]


@pytest.mark.parametrize("backend", BACKENDS)
def test_copies_and_restore_keep_the_resolved_method(backend, water8):
    ig = SymplecticIntegrator(0.001, "kahan-li-6", system=water8.system, backend=backend, groups=None)
    for clone in (pickle.loads(pickle.dumps(ig)), restore(mm.XmlSerializer.deserialize(mm.XmlSerializer.serialize(ig)))):
        assert clone.resolved.substeps == ig.resolved.substeps
        assert clone.resolved.force_evals == ig.resolved.force_evals == 9
        assert clone.resolved.stability == catalogue["kahan-li-6"].stability


# -- option checks, once for both backends ------------------------------------------------------------------------------------
@pytest.mark.parametrize("backend", ["auto", *BACKENDS])
@pytest.mark.parametrize("bad, error, match", [
    (True, TypeError, "truth value, not a time"),
    (np.bool_(True), TypeError, "truth value"),
    (True * unit.picoseconds, TypeError, "truth value"),
    (0.0, ValueError, "positive and finite"),
    (-0.001, ValueError, "positive and finite"),
    (float("nan"), ValueError, "positive and finite"),
    (float("inf"), ValueError, "positive and finite"),
    (2 * unit.nanometers, TypeError, "not a time"),
    ("2 fs", TypeError, "not a time"),
])
def test_bad_step_sizes(backend, bad, error, match, morse):
    with pytest.raises(error, match=match):
        SymplecticIntegrator(bad, "verlet", system=morse.system, backend=backend)
    ig = SymplecticIntegrator(0.001, "verlet", system=morse.system, backend=backend)
    with pytest.raises(error, match=match):
        ig.setStepSize(bad)
    assert ig.getStepSize() == 0.001 * unit.picoseconds


def test_bad_step_size_in_prk_integrator():
    with pytest.raises(TypeError, match="truth value"):
        PRKIntegrator(True, "verlet")


@pytest.mark.parametrize("backend", ["auto", *BACKENDS])
def test_misspelt_option_gets_suggestions(backend, water8):
    with pytest.raises(TypeError, match=r"unknown option 'exact_momentun' \(did you mean 'exact_momentum'\?\)"):
        SymplecticIntegrator(0.001, "verlet", system=water8.system, backend=backend, exact_momentun=True)
    with pytest.raises(TypeError, match=r"'max_sped' \(did you mean 'max_speed'\?\).*accepts"):
        SymplecticIntegrator(0.001, "verlet", backend=backend, max_sped=10)


def test_misspelt_option_on_the_classes(water8):
    with pytest.raises(TypeError, match=r"PRKIntegrator got an unknown option 'tolerence' \(did you mean 'tolerance'"):
        PRKIntegrator(0.001, "gauss-2", tolerence=1e-6)
    with pytest.raises(TypeError, match=r"CustomSymplecticIntegrator got an unknown option 'inner_methd'"):
        CustomSymplecticIntegrator(0.001, "verlet", inner_methd="pefrl")
    if plugin.available():
        with pytest.raises(TypeError, match=r"NativeSymplecticIntegrator got an unknown option 'check_fintie'"):
            NativeSymplecticIntegrator(0.001, "verlet", check_fintie=False)


@needs_native
def test_native_refuses_custom_only_options_and_general_tableaux(water8):
    with pytest.raises(ValueError, match="backend='native' does not take the option.*tolerance"):
        SymplecticIntegrator(0.001, "verlet", backend="native", tolerance=1e-6)
    with pytest.raises(NativeMethodError, match="'gauss-2' is a general .implicit. PRK tableau"):
        NativeSymplecticIntegrator(0.001, "gauss-2", system=water8.system)


@needs_native
def test_the_signature_leaves_out_only_the_ends_placements_two_events():
    """The program signature leaves out a half event flagged FirstOfInterval as the first sub-step and one flagged
    LastOfInterval as the last (what the ends placement is, and what format-4 checkpoints had implied); an event
    anywhere else, or of another fraction, is part of the program (review: sequences differing there shared one)."""
    cls = plugin.swig_module().SymPRKIntegrator
    K, D, T = cls.Kick, cls.Drift, cls.Thermostat
    C, FIRST, LAST = cls.ForcesCached, cls.FirstOfInterval, cls.LastOfInterval

    def signature(kinds, coefficients, flags):
        ig = cls(0.001, kinds, coefficients, [-1] * len(kinds), flags)
        ig.setThermostat(300.0, 0.1, 2, 10, False)
        return ig.getProgramSignature()

    plain = signature([K, D, K], [0.5, 1.0, 0.5], [C, 0, 0])
    assert signature([T, K, D, K, T], [0.5, 0.5, 1.0, 0.5, 0.5], [FIRST, C, 0, 0, LAST]) == plain
    assert signature([K, T, D, K, T], [0.5, 0.5, 1.0, 0.5, 0.5], [C, FIRST, 0, 0, LAST]) != plain  # moved
    assert signature([T, K, D, K, T], [0.25, 0.5, 1.0, 0.5, 0.5], [FIRST, C, 0, 0, LAST]) != plain  # other fraction
