"""The step plan of the native plugin (platforms/openmmapi: SymPRKStepPlan), decided once for every platform, and
each kernel executing exactly it: Reference, CPU (the Reference kernel on the CPU platform's data) and OpenCL
(the Common kernel).

The plugin lists the plan of a bound Context (``getStepPlan``: one line per operation) and, on request, records
what its kernel ran (``setExecutionTraceEnabled`` / ``getExecutionTrace``: step, operation index, force groups
evaluated).  Checked here, for velocity Verlet, PEFRL (velocity projections before some drifts), Yoshida-4, an
r-RESPA sequence of two force groups, and the thermostat every step and every third step, at the ends of the step
and in its middle (``thermostat_position="middle"``: a THERMOSTAT sub-step; with multiple time stepping the middle
of the outer step):

* the plan is the resolved method's sub-steps (``integrator.resolved.substeps``, the whole step: resolve decides it,
  the plugin only executes it): a kick per kick sub-step with its groups (-1 resolved to the integration force
  groups), a projection before each drift or event flagged for one and RATTLE's after the last kick or drift where
  the System has constraints, an event per THERMOSTAT sub-step in the step of each interval its phase names (ends:
  half events in the first and the last step; middle: one in the centre step, (n - 1) // 2), the blow-up check
  after the last velocity-changing operation;
* every step runs the plan's operations in order, the thermostat events only in the steps of their phase;
* forces are evaluated only by kicks, for their own groups, and a step costs getForceEvaluationsPerStep()
  evaluations in steady state (per group with multiple time stepping);
* the three platforms run the same operations and the same evaluations.
"""
import numpy as np
import openmm as mm
import openmm.unit as unit
import pytest

from openmm_symprk import SymplecticIntegrator, catalogue, plugin
from openmm_symprk.methods.resolved import EventPhase, SubstepKind, resolve
from openmm_symprk.systems.forcegroups import split_forces
from helpers import COMMON

pytestmark = pytest.mark.skipif(not plugin.available(), reason=f"native plugin unavailable: {plugin.unavailable_reason()}")

needs_opencl = pytest.mark.skipif(COMMON not in plugin.platforms(), reason=f"no native {COMMON} kernel here")
PLATFORMS = [("Reference", {}), ("CPU", {}),
             pytest.param(COMMON, {"Precision": "double"}, marks=needs_opencl, id=COMMON)]
STEPS = 7
ALL_GROUPS = -1  # the integration force groups' default mask, 0xffffffff, as an int

#: name -> (scene fixture, method, options)
CASES = {
    "verlet": ("water8", "verlet", {}),
    "pefrl": ("water8", "pefrl", {}),
    "yoshida4": ("morse", "yoshida-4", {}),
    "mts": ("morse", "verlet", {"groups": "split"}),
    "nvt-interval1": ("water8", "verlet", {"temperature": 300, "random_seed": 2, "thermostat_position": "ends"}),
    "nvt-interval3": ("water8", "omelyan-2", {"temperature": 300, "thermostat_interval": 3, "random_seed": 2,
                                              "thermostat_position": "ends"}),
    "nvt-middle": ("water8", "verlet", {"temperature": 300, "random_seed": 2, "thermostat_position": "middle"}),
    "nvt-middle-interval3": ("water8", "omelyan-2", {"temperature": 300, "thermostat_interval": 3, "random_seed": 2,
                                                      "thermostat_position": "middle"}),
    "nvt-middle-mts": ("morse", "verlet", {"groups": "split", "temperature": 300, "random_seed": 2,
                                           "thermostat_interval": 2, "thermostat_position": "middle"}),
}


def parse(line):
    """A plan line: (kind, {key: value}, set of bare words)."""
    kind, *tokens = line.split()
    facts = dict(t.split("=", 1) for t in tokens if "=" in t)
    return kind, facts, {t for t in tokens if "=" not in t}


def _build(case, request):
    scene_name, method, options = CASES[case]
    scene = request.getfixturevalue(scene_name)
    system = scene.system
    options = dict(options)
    if options.get("groups") == "split":
        system = mm.XmlSerializer.clone(system)
        options["groups"] = split_forces(system, slow=["CustomAngleForce", 2], substeps=2)
    return scene, system, lambda: SymplecticIntegrator(1 * unit.femtoseconds, method, system=system, backend="native",
                                                       **options)


def _run(case, platform, props, request):
    scene, system, make = _build(case, request)
    ig = make()
    ctx = mm.Context(system, ig, mm.Platform.getPlatformByName(platform), props)
    ctx.setPositions(scene.positions)
    ctx.setVelocities(scene.velocities)
    ig.setExecutionTraceEnabled(True)
    ig.step(STEPS)
    trace = np.asarray(ig.getExecutionTrace(), dtype=np.int64).reshape(-1, 3)
    return ig, system, list(ig.getStepPlan()), trace


def _expected_plan(ig, constrained):
    """The plan's lines as the resolved sub-steps say they must be (kind, substep, groups, reuse, phase): the plugin
    executes ``ig.resolved.substeps`` and decides nothing of its own."""
    out = []
    interval = ig.getThermostatInterval() if ig.hasThermostat() else 1
    subs = ig.resolved.substeps
    last = max(i for i, sub in enumerate(subs) if sub.is_kick_or_drift)
    for s, sub in enumerate(subs):
        if sub.kind == SubstepKind.THERMOSTAT:  # after a kick, under constraints: velocities projected first
            if constrained and sub.project_before:
                out.append(("project", s, None, None, None))
            out.append(("thermostat", s, None, None, sub.phase.step_in(interval)))
        elif sub.kind == SubstepKind.KICK:
            out.append(("kick", s, ig.getIntegrationForceGroups() if sub.group_mask == -1 else sub.group_mask,
                        sub.forces_cached, None))
        else:
            if constrained and sub.project_before:
                out.append(("project", s, None, None, None))
            out.append(("drift", s, None, None, None))
        if s == last and constrained:  # RATTLE's closing projection
            out.append(("project", None, None, None, None))
    return out, interval


def _trace_of(plan_lines, trace, steps):
    """{step: [resolved sub-step index, or "project" for the closing projection, of every operation run]}."""
    operations = [parse(line) for line in plan_lines]
    out = {}
    for step in range(1, steps + 1):
        out[step] = [int(operations[op][1]["substep"]) if "substep" in operations[op][1] else "project"
                     for op in trace[trace[:, 0] == step][:, 1]]
    return out


@pytest.mark.parametrize("platform,props", PLATFORMS)
@pytest.mark.parametrize("case", sorted(CASES))
def test_each_kernel_runs_the_plan(case, platform, props, request):
    ig, system, plan, trace = _run(case, platform, props, request)
    constrained = system.getNumConstraints() > 0
    expected, interval = _expected_plan(ig, constrained)
    parsed = [parse(line) for line in plan]

    # the plan states the sequence and the settings
    got = []
    for kind, facts, words in parsed:
        got.append((kind, int(facts["substep"]) if "substep" in facts else None,
                    int(facts["groups"], 16) - (1 << 32) * (int(facts["groups"], 16) >= 1 << 31) if "groups" in facts else None,
                    ("reuse" in words) if kind == "kick" else None,
                    int(facts["phase"].split("/")[0]) if kind == "thermostat" else None))
    assert got == expected, "\n".join(plan)
    for (kind, facts, _), (_, s, *_) in zip(parsed, expected):
        if kind in ("kick", "drift", "thermostat"):
            assert float(facts["c"]) == pytest.approx(float(ig.resolved.substeps[s].coefficient), rel=1e-5)
        if kind == "thermostat":
            assert float(facts["c"]) in (0.5, 1.0) and facts["phase"].endswith(f"/{interval}")
    changes = [i for i, (kind, _, _) in enumerate(parsed) if kind == "kick" or (kind == "drift" and constrained)]
    assert [i for i, (_, _, words) in enumerate(parsed) if "check" in words] == changes[-1:]
    mts = len({g for k, _, g, _, _ in expected if k == "kick"}) > 1
    assert all(("copy" in words) == mts for kind, _, words in parsed if kind == "kick")

    # every step runs the plan's operations in order, the thermostat's only in the steps of their phase
    for step in range(1, STEPS + 1):
        ran = trace[trace[:, 0] == step]
        runs = [i for i, (kind, _, _, _, phase) in enumerate(expected)
                if kind != "thermostat" or (step - 1) % interval == phase]
        assert ran[:, 1].tolist() == runs, f"step {step}: ran {ran[:, 1].tolist()}, plan {plan}"
        # forces are evaluated by kicks only, for their own groups
        for op, evaluated in ran[:, 1:]:
            assert evaluated == 0 or (expected[op][0] == "kick" and evaluated == expected[op][2]), (step, op, evaluated)
        # a kick that does not reuse forces always evaluates them
        assert all(evaluated != 0 for op, evaluated in ran[:, 1:] if expected[op][0] == "kick" and not expected[op][3])
        if step > 1:  # steady state: the cached forces of the last step's closing kick serve the opening one
            assert np.count_nonzero(ran[:, 2]) == ig.getForceEvaluationsPerStep(), (step, ran.tolist())
    middle = [i for i, e in enumerate(expected)
              if e[0] == "thermostat" and ig.resolved.substeps[e[1]].phase is EventPhase.CENTRE]
    if middle:  # one event, at the centre of the (outer) step, run from its closing kicks: the k kicks it begins with
        # are its opening and closing ones, so k fewer sub-steps follow the event than precede it
        n, at = ig.getNumSubsteps(), expected[middle[0]][1]
        k = next(i for i, s in enumerate(ig.resolved.substeps) if s.kind != SubstepKind.KICK)
        assert len(middle) == 1 and k >= 1 and n - 1 - at == at - k
    if mts:  # per group: the slow group once a step, the fast one twice
        steady = trace[(trace[:, 0] > 1) & (trace[:, 2] != 0)]
        per_group = {int(g): int(np.count_nonzero(steady[:, 2] == g)) // (STEPS - 1) for g in set(steady[:, 2].tolist())}
        assert per_group == {1 << 1: 1, 1 << 0: 2}, per_group
    if ig.hasThermostat():
        events = trace[np.isin(trace[:, 1], [i for i, e in enumerate(expected) if e[0] == "thermostat"])]
        if middle:  # one event in the middle step of each interval
            assert events[:, 0].tolist() == [k for k in range(1, STEPS + 1) if (k - 1) % interval == (interval - 1) // 2]
        else:
            assert len(events) == 2 * (STEPS // interval) + (STEPS % interval > 0)


@needs_opencl
@pytest.mark.parametrize("case", sorted(CASES))
def test_platforms_run_the_same_operations(case, request):
    """The plan is the API layer's, so the same on every platform; the kernels run the same operations and make the
    same force evaluations, step for step."""
    runs = [_run(case, platform, props, request) for platform, props in
            [("Reference", {}), ("CPU", {}), (COMMON, {"Precision": "double"})]]
    for _, _, plan, trace in runs[1:]:
        assert plan == runs[0][2]
        np.testing.assert_array_equal(trace, runs[0][3])


def test_trace_is_off_unless_asked_and_the_plan_needs_a_context(water8):
    ig = SymplecticIntegrator(1 * unit.femtoseconds, "verlet", system=water8.system, backend="native")
    with pytest.raises(mm.OpenMMException, match="create the Context first"):
        ig.getStepPlan()
    ctx = mm.Context(water8.system, ig, mm.Platform.getPlatformByName("Reference"))
    ctx.setPositions(water8.positions)
    ig.step(2)
    assert len(ig.getExecutionTrace()) == 0
    ig.setExecutionTraceEnabled(True)
    ig.step(1)
    assert len(ig.getExecutionTrace()) == 3 * len(ig.getStepPlan())
    ig.setExecutionTraceEnabled(False)
    ig.step(1)
    assert len(ig.getExecutionTrace()) == 3 * len(ig.getStepPlan())


def test_the_plan_follows_the_integration_force_groups(morse):
    """-1 (a kick of the integration force groups) is resolved in the plan, made again when those groups change."""
    system = mm.XmlSerializer.clone(morse.system)
    for i, f in enumerate(system.getForces()):
        f.setForceGroup(i % 2)
    ig = SymplecticIntegrator(1 * unit.femtoseconds, "verlet", system=system, backend="native")
    ctx = mm.Context(system, ig, mm.Platform.getPlatformByName("Reference"))
    ctx.setPositions(morse.positions)
    assert [parse(line)[1]["groups"] for line in ig.getStepPlan() if line.startswith("kick")] == ["0xffffffff"] * 2
    ig.setIntegrationForceGroups(1 << 1)
    ig.setExecutionTraceEnabled(True)
    ig.step(2)
    assert [parse(line)[1]["groups"] for line in ig.getStepPlan() if line.startswith("kick")] == ["0x2"] * 2
    evaluated = set(np.asarray(ig.getExecutionTrace()).reshape(-1, 3)[:, 2].tolist()) - {0}
    assert evaluated == {1 << 1}


#: every catalogue splitting and composition (what the native backend runs)
SPLITTINGS = sorted({m.name for m in catalogue.values() if m.splitting is not None})


def _placements(name):
    out = ["ends"]
    try:
        resolve(name, constraints=True, thermostat_position="middle")
        out.append("middle")
    except ValueError:
        pass  # not symmetric: no centre
    return out


@pytest.mark.parametrize("interval", [1, 3])
@pytest.mark.parametrize("name", SPLITTINGS + ["mts"])
def test_the_plugin_runs_the_resolved_substeps(name, interval, water8, morse):
    """For every catalogue splitting, both placements (where the method has a centre), multiple time stepping and a
    thermostat every step and every third: each step runs exactly the resolved sub-steps (the events only in the step
    of the interval their phase names; a projection flagged before an event in every step), in order, RATTLE's
    projection right after the last kick or drift."""
    scene = water8 if name != "mts" else morse
    system, options = scene.system, {}
    if name == "mts":
        system = mm.XmlSerializer.clone(system)
        options["groups"] = split_forces(system, slow=["CustomAngleForce", 2], substeps=2)
    constrained = system.getNumConstraints() > 0
    for position in _placements("verlet" if name == "mts" else name):
        ig = SymplecticIntegrator(0.5 * unit.femtoseconds, "verlet" if name == "mts" else name, system=system,
                                  backend="native", temperature=300, thermostat_interval=interval, random_seed=3,
                                  thermostat_position=position, **options)
        ctx = mm.Context(system, ig, mm.Platform.getPlatformByName("Reference"))
        ctx.setPositions(scene.positions)
        ctx.setVelocities(scene.velocities)
        ig.setExecutionTraceEnabled(True)
        steps = 2 * interval
        ig.step(steps)
        ran = _trace_of(ig.getStepPlan(), np.asarray(ig.getExecutionTrace()).reshape(-1, 3), steps)
        subs = ig.resolved.substeps
        last = max(i for i, sub in enumerate(subs) if sub.is_kick_or_drift)
        for step in range(1, steps + 1):
            expected = []
            for i, sub in enumerate(subs):
                if constrained and sub.project_before:
                    expected.append(i)  # its projection (every step), named by the sub-step it precedes
                if sub.kind == SubstepKind.THERMOSTAT and (step - 1) % interval != sub.phase.step_in(interval):
                    continue
                expected.append(i)
                if i == last and constrained:
                    expected.append("project")
            assert ran[step] == expected, (name, position, step)
        assert ig.resolved.thermostat_position == position
        del ctx
