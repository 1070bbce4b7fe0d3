"""Bad input gets a clear error naming the bad value; systems that cannot conserve get one warning."""
import warnings

import numpy as np
import openmm as mm
import openmm.unit as unit
import pytest

from helpers import stiff_diatomic
from openmm_symprk import PRKIntegrator, PRKTableau, SimulationBlowUpError, SymplecticIntegrator, TableauError
from openmm_symprk.methods.catalogue import UnknownMethodError
from openmm_symprk.integrators import ConstraintSupportError
from openmm_symprk.integrators import SystemMismatchError
from openmm_symprk.systems.checks import ConservationWarning


@pytest.mark.parametrize("bad", [0, -1.0, -2 * unit.femtoseconds, float("nan"), float("inf")])
def test_non_positive_step_sizes(bad):
    with pytest.raises(ValueError, match="step size must be positive"):
        SymplecticIntegrator(bad, "verlet")


@pytest.mark.parametrize("bad", [2 * unit.nanometer, "2 fs", None])
def test_step_size_must_be_a_time(bad):
    with pytest.raises(TypeError, match="is not a time"):
        SymplecticIntegrator(bad, "verlet")


def test_set_step_size_is_validated():
    ig = SymplecticIntegrator(1 * unit.femtoseconds, "verlet")
    ig.setStepSize(2 * unit.femtoseconds)
    assert ig.getStepSize() == 0.002 * unit.picoseconds
    with pytest.raises(ValueError, match="-0.001"):
        ig.setStepSize(-0.001)


def test_unknown_method():
    with pytest.raises(UnknownMethodError, match="Did you mean 'pefrl'"):
        SymplecticIntegrator(0.001, "pefr")


def test_nonsymplectic_refused_unless_opted_in():
    with pytest.raises(TableauError, match=r"rk4 is not symplectic.*residual 1\.\d+e-01"):
        SymplecticIntegrator(0.001, "rk4")
    SymplecticIntegrator(0.001, "rk4", allow_nonsymplectic=True)  # opted in: no error
    bad = PRKTableau([[0, 0], [1, 0]], [0.5, 0.5], [[0, 0], [1, 0]], [0.5, 0.5], name="heun")
    with pytest.raises(TableauError, match="heun is not symplectic"):
        PRKIntegrator(0.001, bad)


def test_general_tableau_without_system_is_refused_on_a_constrained_context(water8):
    """Without system= nothing can be checked at construction: the first step's probe of the Context finds the
    constraints the tableau cannot keep and says so."""
    ig = SymplecticIntegrator(0.001, "gauss-2")
    ctx = water8.context(ig)  # noqa: F841
    with pytest.raises(SystemMismatchError, match="general PRK tableau.*has constraints"):
        ig.step(1)


def test_general_tableau_with_constraints_is_a_clear_error(water8):
    with pytest.raises(ConstraintSupportError, match="'gauss-2'.*constraints.*'verlet'"):
        SymplecticIntegrator(0.001, "gauss-2", system=water8.system)
    user = PRKTableau([["1/4", "-0.0386751345948128822545743902509787"],
                       ["0.5386751345948128822545743902509787", "1/4"]], ["1/2", "1/2"],
                      [["1/4", "-0.0386751345948128822545743902509787"],
                       ["0.5386751345948128822545743902509787", "1/4"]], ["1/2", "1/2"], name="my-gauss")
    with pytest.raises(ConstraintSupportError, match="my-gauss"):
        PRKIntegrator(0.001, user, system=water8.system)


def test_user_splitting_tableau_runs_with_constraints(water8):
    """A user tableau in splitting form compiles to RATTLE like the catalogue methods."""
    tab = PRKTableau([[0, 0], [1, 0]], [1, 0], [[0.5, 0], [0.5, 0.5]], [0.5, 0.5], name="my-verlet")
    ig = PRKIntegrator(2 * unit.femtoseconds, tab, system=water8.system)
    assert ig.resolved.form == "splitting" and ig.program_info.rattle
    ctx = water8.context(ig)
    ig.step(10)


def test_bad_options():
    with pytest.raises(ValueError, match="tolerance must be a positive number of nm, got -1"):
        SymplecticIntegrator(0.001, "gauss-2", tolerance=-1)
    with pytest.raises(ValueError, match="max_iterations must be at least 1, got 0"):
        SymplecticIntegrator(0.001, "gauss-2", max_iterations=0)
    with pytest.raises(TypeError, match="openmm.System"):
        SymplecticIntegrator(0.001, "verlet", system="not a system")


def test_blow_up_names_step_and_method():
    system = stiff_diatomic()
    h = 1.7 / np.sqrt(2 * 1.0e5)  # h*omega = 1.7, just beyond yoshida-4's stability limit 1.5734

    def run(steps):
        ig = SymplecticIntegrator(h, "yoshida-4", system=system)
        ctx = mm.Context(system, ig, mm.Platform.getPlatformByName("Reference"))
        ctx.setPositions([mm.Vec3(0, 0, 0), mm.Vec3(0.11, 0, 0)])
        return ig, ctx

    ig, ctx = run(0)
    with pytest.raises(SimulationBlowUpError, match=r"blew up at integrator step (\d+) with method 'yoshida-4'.*1\.5734") as info:
        ig.step(1000)
    import re

    step = int(re.search(r"step (\d+)", str(info.value)).group(1))
    assert 1 < step < 1000
    # the step named is the first non-finite one: one step earlier everything is still finite
    ig2, ctx2 = run(0)
    ig2.step(step - 1)
    v = ctx2.getState(getVelocities=True).getVelocities(asNumpy=True)._value
    assert np.all(np.isfinite(v))
    with pytest.raises(SimulationBlowUpError, match=f"step {step} "):
        ig2.step(1)


def test_conservation_warnings_once(water8):
    import copy

    system = copy.deepcopy(water8.system)
    system.addForce(mm.CMMotionRemover())
    with warnings.catch_warnings(record=True) as rec:
        warnings.simplefilter("always")
        SymplecticIntegrator(0.001, "verlet", system=system)
        SymplecticIntegrator(0.001, "verlet", system=system)
    msgs = [str(w.message) for w in rec if issubclass(w.category, ConservationWarning)]
    assert len(msgs) == 1 and "CMMotionRemover" in msgs[0] and "angular momentum" in msgs[0]


def test_a_periodic_box_warns_only_with_exact_momentum_which_it_refuses():
    system = mm.System()
    system.setDefaultPeriodicBoxVectors(mm.Vec3(2, 0, 0), mm.Vec3(0, 2, 0), mm.Vec3(0, 0, 2))
    system.addParticle(1.0)
    nb = mm.NonbondedForce()
    nb.setNonbondedMethod(mm.NonbondedForce.PME)
    nb.addParticle(0, 0.3, 0.1)
    system.addForce(nb)
    with warnings.catch_warnings():  # NVE in a box: angular momentum is not what the run is for
        warnings.simplefilter("error", ConservationWarning)
        SymplecticIntegrator(0.001, "verlet", system=system)
    with pytest.warns(ConservationWarning, match="periodic boundary conditions break rotational symmetry"):
        with pytest.raises(ValueError, match="periodic"):
            SymplecticIntegrator(0.001, "verlet", system=system, exact_momentum=True)
