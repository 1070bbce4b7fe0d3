"""The studies' one row type: labels read back to the same row, the earlier grammars map onto it, bad labels are
refused naming the bad part, evaluations come from the resolved method, and each row builds its integrator."""
import warnings

import numpy as np
import openmm as mm
import openmm.unit as unit
import pytest

from openmm_symprk.integrators import SymplecticIntegrator
from openmm_symprk.methods.resolved import resolve
from openmm_symprk.studies.core.rows import Row, split_groups

LABELS = ["verlet 0.5 fs", "omelyan-2 4 fs SVR 1 ps", "langevin 4 fs friction 1/ps HMR 3 Da",
          "mts-langevin 3/2 fs friction 1/ps", "nose-hoover 2 fs 1/ps", "dpd 2 fs friction 1/ps cutoff 0.9 nm",
          "omelyan-2/verlet 6/2 fs", "openmm-mts 4/2 fs", "rigid:omelyan-2 4 fs", "openmm-verlet 2 fs",
          "verlet 2 fs SVR 0.1 ps every 10 middle T 310 K exact-momentum native seed 4", "pefrl 4 fs custom"]


@pytest.mark.parametrize("label", LABELS)
def test_label_round_trips(label):
    row = Row.parse(label)
    assert row.label == label
    assert Row.parse(row.label) == row


def test_preset_tables_are_rows():
    """Every row of the preset tables reads as a Row whose label reads back to it."""
    from openmm_symprk.studies.bench import presets as bench
    from openmm_symprk.studies.fidelity.presets import ROWS
    from openmm_symprk.studies.fidelity.rowspec import to_row
    from openmm_symprk.studies.nvt.rows import COST_ROWS

    rows = [Row.parse(label) for _, label, _ in COST_ROWS] + [to_row(r) for r in ROWS]
    for sc in bench.production()["scenes"].values():
        rows += [Row.parse(name, step_fs=h) for name, h in sc["rows"]]
    for row in rows:
        assert Row.parse(row.label) == row


@pytest.mark.parametrize("old, step, label", [
    ("verlet@mts2", 4.0, "verlet 4/2 fs"), ("omelyan-2/verlet@mts1", 4.8, "omelyan-2/verlet 4.8/1 fs"),
    ("openmm-mts4", 6.0, "openmm-mts 6/4 fs"), ("openmm-langevin", 2.0, "langevin 2 fs friction 1/ps"),
    ("openmm-nosehoover", 2.0, "nose-hoover 2 fs 1/ps"), ("omelyan-2@4", None, "omelyan-2 4 fs"),
    ("nosehoover@2", None, "nose-hoover 2 fs 1/ps"), ("yoshida4", 1.0, "yoshida-4 1 fs")])
def test_earlier_grammars(old, step, label):
    assert Row.parse(old, step_fs=step).label == label


@pytest.mark.parametrize("label, says", [
    ("verlt 2 fs", "unknown method 'verlt'"), ("verlet", "no step"), ("verlet 2 fs foo", "'foo' not understood"),
    ("langevin 2 fs SVR 1 ps", "SVR does not apply"), ("verlet 2 fs every 3", "need a thermostat"),
    ("verlet 0 fs", "positive"), ("openmm-mts 2 fs", "inner steps"), ("openmm-verlet 2 fs native", "backend"),
    ("verlet 2 fs SVR x ps", "SVR needs a number")])
def test_bad_labels_are_refused(label, says):
    with pytest.raises(ValueError, match=says):
        Row.parse(label)


def test_evaluations_come_from_the_resolved_method():
    for label in ("verlet 2 fs", "yoshida-4 2 fs", "omelyan-2/verlet 6/2 fs", "kahan-li-8 1 fs"):
        row = Row.parse(label)
        expect = resolve(row.method, True, groups=split_groups(row.mts) if row.mts else None,
                         inner_method=row.inner or None).force_evals
        assert row.evals_per_step(True) == expect
        assert row.evals_per_ps(True) == pytest.approx(expect / row.h_ps)
    assert Row.parse("yoshida-4 1 fs").evals_per_step() == 3
    assert Row.parse("openmm-mts 4/3 fs").evals_per_step() == 4
    assert Row.parse("langevin 2 fs").evals_per_step() == 1


def test_what_a_row_knows():
    svr, lang, nh, verlet = (Row.parse(t) for t in ("verlet 2 fs SVR 0.1 ps", "langevin 2 fs", "nose-hoover 2 fs",
                                                     "openmm-verlet 2 fs"))
    assert (svr.thermostat, svr.ensemble, svr.has_heat_bath, svr.keeps_momentum, svr.leapfrog) == \
        ("svr", "NVT", True, True, False)
    assert (lang.thermostat, lang.has_heat_bath, lang.keeps_momentum, lang.leapfrog) == \
        ("langevin", False, False, True)
    assert nh.has_heat_bath and not nh.leapfrog and nh.conserves_effective_energy
    assert verlet.ensemble == "NVE" and verlet.leapfrog and not verlet.has_heat_bath and verlet.conserves_effective_energy
    # the package's middle placement holds the velocities before the step's closing kicks too (its step runs from
    # them): half a kick for velocity Verlet, omelyan-2's closing b h, both levels' for multiple time stepping; the
    # ends placement and NVE hold on-step velocities
    lags = [Row.parse(t).velocity_lag for t in ("verlet 2 fs SVR 0.1 ps middle", "verlet 2 fs SVR 0.1 ps auto",
                                                "verlet 4/2 fs SVR 0.1 ps middle", "omelyan-2 2 fs SVR 0.1 ps middle",
                                                "omelyan-2 2 fs SVR 0.1 ps", "verlet 2 fs")]
    assert lags[0] == lags[1] == ((0.5, None),) and lags[4] == lags[5] == ()
    assert len(lags[2]) == 2 and {g for _, g in lags[2]} == {(1,), (0,)} and lags[3][0][0] == pytest.approx(0.1932, abs=1e-4)


def _system(n=4):
    system = mm.System()
    force = mm.CustomExternalForce("0.5*k*(x^2+y^2+z^2)")
    force.addGlobalParameter("k", 100.0)
    for i in range(n):
        system.addParticle(2.0)
        force.addParticle(i, [])
    system.addForce(force)
    return system


def test_build_openmm_integrators():
    system = _system()
    cases = {"openmm-verlet 2 fs": mm.VerletIntegrator, "langevin 2 fs friction 3/ps T 250 K": mm.LangevinMiddleIntegrator,
             "nose-hoover 1 fs 2/ps": mm.NoseHooverIntegrator, "dpd 2 fs cutoff 0.8 nm": mm.DPDIntegrator}
    for label, cls in cases.items():
        ig = Row.parse(label).build(system, seed=5, constraint_tolerance=1e-7)
        assert isinstance(ig, cls)
        assert ig.getStepSize().value_in_unit(unit.picosecond) == pytest.approx(Row.parse(label).h_ps)
        assert ig.getConstraintTolerance() == pytest.approx(1e-7)
    lang = Row.parse("langevin 2 fs friction 3/ps T 250 K").build(system, seed=5)
    assert lang.getFriction().value_in_unit(unit.picosecond ** -1) == pytest.approx(3.0)
    assert lang.getTemperature().value_in_unit(unit.kelvin) == pytest.approx(250.0)
    assert lang.getRandomNumberSeed() == 5


def test_build_ours():
    system = _system()
    ig = Row.parse("omelyan-2 4 fs SVR 0.5 ps every 3 T 310 K custom seed 9").build(system)
    assert isinstance(ig, SymplecticIntegrator) and ig.method_name == "omelyan-2" and ig.backend == "custom"
    th = ig.thermostat
    assert (th.temperature, th.collision_time, th.interval, th.seed) == (310.0, 0.5, 3, 9)
    assert Row.parse("verlet 2 fs").build(system).thermostat is None


def test_a_row_without_a_position_word_runs_the_ends():
    """Stored results of rows without a position word were run with the ends placement: such a row still runs
    the ends, though the integrator's default ("auto") puts verlet's thermostat in the middle."""
    system = _system()
    ig = Row.parse("verlet 2 fs SVR 0.1 ps middle custom").build(system)
    assert ig.thermostat.position == "middle"
    assert Row.parse("verlet 2 fs SVR 0.1 ps custom").build(system).thermostat_position == "ends"
    assert Row.parse("verlet 2 fs SVR 0.1 ps auto custom").build(system).thermostat_position == "middle"
    assert Row.parse("verlet 2 fs SVR 0.1 ps").label == Row.parse("verlet 2 fs SVR 0.1 ps ends").label


def test_leapfrog_state_lags_half_a_step():
    """The engine starts a leapfrog row from v(-h/2) = v - (h/2) F/m, an on-step row from v itself, and a leapfrog
    row with start=False from v as given."""
    from openmm_symprk.studies.core.engine import RowEngine

    system = _system()
    x = np.array([[0.1, 0.0, 0.0], [0.0, 0.2, 0.0], [0.0, 0.0, -0.1], [0.05, 0.05, 0.0]])
    v = np.ones((4, 3))
    for label, lag, start in (("openmm-verlet 2 fs", True, True), ("langevin 2 fs", True, True),
                              ("verlet 2 fs", False, True), ("openmm-verlet 2 fs", False, False),
                              ("verlet 2 fs SVR 0.1 ps middle", True, True)):
        row = Row.parse(label)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # the harmonic wells' ConservationWarning
            got = RowEngine(row, system, x, v, platform="Reference", start=start).sample(energy=False).v
        expect = v + 0.5 * row.h_ps * 100.0 * x / 2.0 if lag else v
        np.testing.assert_allclose(got, expect, rtol=1e-12)


def test_numbers_in_a_label_read_back_exactly():
    """A bisected or divided step (the bench's stability probes and reference runs) is written with every digit."""
    row = Row("verlet", 300.0 / 1234)
    assert Row.parse(row.label) == row and Row.parse("verlet 0.5 fs").label == "verlet 0.5 fs"


def test_the_grammar_names_the_placements_and_the_rows_default():
    """A bad position word is refused naming the placements (methods.placement.POSITIONS) and what a row without
    one runs: the ends, which is not SymplecticIntegrator's default."""
    from openmm_symprk.methods.placement import POSITIONS
    from openmm_symprk.studies.core.rows import ROW_POSITION

    with pytest.raises(ValueError, match=f"{' | '.join(POSITIONS)}; none: {ROW_POSITION}"):
        Row.parse("verlet 2 fs SVR 0.1 ps centre")
    assert ROW_POSITION == "ends" and Row.parse("verlet 2 fs SVR 0.1 ps").position == ROW_POSITION
    with warnings.catch_warnings():  # the difference the grammar states: verlet's default is the middle
        warnings.simplefilter("ignore")  # the harmonic wells' ConservationWarning
        ig = SymplecticIntegrator(0.002, "verlet", system=_system(), temperature=300.0, backend="custom")
    assert ig.thermostat_position != ROW_POSITION == Row.parse("verlet 2 fs SVR 0.1 ps custom").build(
        _system()).thermostat_position


@pytest.mark.parametrize("scene", ["oscillators", "water"])
def test_on_step_velocities_of_a_leapfrog_row_are_velocity_verlets(scene):
    """Known answer: OpenMM's VerletIntegrator started from v(-h/2) runs velocity Verlet's positions, and its
    velocities brought to the positions' time (sample(on_step=True)) are velocity Verlet's on-step velocities: the
    package's verlet from the same state gives them to round-off on harmonic oscillators, and to the constraint
    tolerance on a rigid-water cluster (SETTLE); the State's own velocities are off by half a kick."""
    from openmm_symprk.studies.core.engine import RowEngine
    from openmm_symprk.systems.scenes import water_cluster
    from openmm_symprk.systems.scenes.builders import harmonic_oscillators

    if scene == "oscillators":
        system, x, v = harmonic_oscillators(50, 2.0e4, 300.0)
        tol = 1e-11
    else:
        cluster = water_cluster(8)
        system, x, v = cluster.system, cluster.positions, cluster.velocities
        tol = 1e-7
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        leap = RowEngine(Row.parse("openmm-verlet 1 fs"), system, x, v, platform="Reference")
        ours = RowEngine(Row.parse("verlet 1 fs native"), system, x, v, platform="Reference")
    for _ in range(3):
        leap.step(7)
        ours.step(7)
        a, b, lagging = leap.sample(on_step=True), ours.sample(), leap.sample()
        scale = np.abs(b.v).max()
        np.testing.assert_allclose(a.x, b.x, atol=tol)
        assert np.abs(a.v - b.v).max() < tol * 10 * scale, np.abs(a.v - b.v).max()
        assert np.abs(lagging.v - b.v).max() > 1e-4 * scale  # half a kick away
    # sampling on-step leaves the run as it was: the next steps agree as before
    leap.step(5)
    ours.step(5)
    np.testing.assert_allclose(leap.sample().x, ours.sample().x, atol=tol)


@pytest.mark.parametrize("label", ["omelyan-2 2 fs", "verlet 4/2 fs", "verlet 1 fs"])
def test_a_middle_placement_rows_on_step_velocities_are_its_methods(label):
    """Known answer: with a collision time so long that its events change nothing (1e9 ps), a row with the thermostat
    in the middle (its step run from its closing kicks, the State behind by them) started from a state and sampled
    on-step has the positions and on-step velocities of the same method without a thermostat: omelyan-2 (closing
    kick b h), multiple time stepping (both levels' closing kicks) and Verlet; the State's own velocities lag."""
    from openmm_symprk.studies.core.engine import RowEngine
    from openmm_symprk.systems.scenes.builders import harmonic_oscillators

    system, x, v = harmonic_oscillators(30, 2.0e4, 300.0)
    if "/" in label:  # multiple time stepping: a slow group 1 and a fast group 0
        for k, f in enumerate(system.getForces()):
            f.setForceGroup(k % 2)
        slow = mm.CustomExternalForce("0.5*k2*(x^2+y^2+z^2)")
        slow.addGlobalParameter("k2", 3.0e3)
        slow.setForceGroup(1)
        for i in range(system.getNumParticles()):
            slow.addParticle(i, [])
        system.addForce(slow)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        middle = RowEngine(Row.parse(f"{label} SVR 1e9 ps middle"), system, x, v, platform="Reference")
        plain = RowEngine(Row.parse(label), system, x, v, platform="Reference")
    assert middle.lag
    for _ in range(3):
        middle.step(5)
        plain.step(5)
        a, b, lagging = middle.sample(on_step=True), plain.sample(), middle.sample()
        scale = np.abs(b.v).max()
        np.testing.assert_allclose(a.x, b.x, atol=1e-7)
        assert np.abs(a.v - b.v).max() < 1e-5 * scale, np.abs(a.v - b.v).max() / scale
        assert np.abs(lagging.v - b.v).max() > 1e-3 * scale  # the closing kicks away
