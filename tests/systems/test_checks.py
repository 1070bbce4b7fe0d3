"""What a System lets a simulation conserve: one issue per kind (CMMotionRemover, virtual sites, frozen atoms,
periodic box, thermostat and barostat forces, external fields), each warned once per process; exact momentum
refused where the System is not isolated."""
import copy
import warnings

import openmm as mm
import openmm.unit as unit
import pytest

from openmm_symprk.systems.checks import (ConservationWarning, conservation_issues, integrator_issues,
                                          validate_system, warn_conservation, warn_once)


def _periodic(system):
    nb = mm.NonbondedForce()
    nb.setNonbondedMethod(mm.NonbondedForce.CutoffPeriodic)
    nb.setCutoffDistance(0.9)
    for _ in range(system.getNumParticles()):
        nb.addParticle(0.0, 0.3, 0.5)
    system.setDefaultPeriodicBoxVectors(mm.Vec3(2, 0, 0), mm.Vec3(0, 2, 0), mm.Vec3(0, 0, 2))
    system.addForce(nb)


def _external(system):
    field = mm.CustomExternalForce("k*x")
    field.addGlobalParameter("k", 1.0)
    field.addParticle(0, [])
    system.addForce(field)


def _centroid(system):
    f = mm.CustomCentroidBondForce(2, "k*distance(g1, g2)^2")
    f.addGlobalParameter("k", 1.0)
    f.addGroup([0, 1])
    f.addGroup([2, 3])
    f.addBond([0, 1], [])
    system.addForce(f)


def _frozen(system):
    system.setParticleMass(2, 0.0)


MODIFICATIONS = {  # kind -> (what makes it, words its message must hold)
    "cmmotionremover": (lambda s: s.addForce(mm.CMMotionRemover()), "linear momentum is reset"),
    "periodic": (_periodic, "angular momentum is not a conserved quantity"),
    "andersenthermostat": (lambda s: s.addForce(mm.AndersenThermostat(300.0, 1.0)), "AndersenThermostat"),
    "montecarlobarostat": (lambda s: s.addForce(mm.MonteCarloBarostat(1.0, 300.0)), "MonteCarloBarostat"),
    "customexternalforce": (_external, "external field"),
    "customcentroidbondforce": (_centroid, "CustomCentroidBondForce"),
    "frozen": (_frozen, "1 massless particle(s) that are not virtual sites (frozen atoms, e.g. particle 2)"),
}


def _isolated(build):
    return build.chain().system


def test_an_isolated_system_has_no_issue(build):
    assert conservation_issues(_isolated(build)) == []


@pytest.mark.parametrize("kind", sorted(MODIFICATIONS))
def test_each_kind_of_issue_is_found_alone(build, kind):
    system = _isolated(build)
    make, words = MODIFICATIONS[kind]
    make(system)
    issues = conservation_issues(system)
    assert [k for k, _ in issues] == [kind]
    assert words in issues[0][1]


def test_virtual_sites_are_an_issue(build):
    assert [k for k, _ in conservation_issues(build.tip4p_waters(2).system)] == ["virtualsites"]


@pytest.mark.parametrize("name", ["LangevinIntegrator", "LangevinMiddleIntegrator", "BrownianIntegrator"])
def test_thermostat_integrators_are_an_issue(name):
    integrator = getattr(mm, name)(300.0, 1.0, 0.001)
    (key, msg), = integrator_issues(integrator)
    assert key == name.lower() and "heat bath" in msg


def test_energy_conserving_integrators_are_not():
    from openmm_symprk import SymplecticIntegrator

    assert integrator_issues(mm.VerletIntegrator(0.001)) == []
    assert integrator_issues(SymplecticIntegrator(1 * unit.femtoseconds, "verlet")) == []


def _warned(fn):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = fn()
    return [w for w in caught if issubclass(w.category, ConservationWarning)], result


def test_each_kind_is_warned_once_per_process(build):
    system = _isolated(build)
    for kind in ("cmmotionremover", "frozen", "customexternalforce"):
        MODIFICATIONS[kind][0](system)
    first, issues = _warned(lambda: warn_conservation(system, "my-integrator"))
    assert len(issues) == 3
    assert sorted(str(w.message).split(":")[0] for w in first) == ["my-integrator"] * 3
    assert {warn_once.seen(k) for k in ("cmmotionremover", "frozen", "customexternalforce")} == {True}
    # the same kinds again, even from another System: nothing, though the issues are still returned
    again, issues = _warned(lambda: warn_conservation(copy.deepcopy(system), "my-integrator"))
    assert again == [] and len(issues) == 3
    # a new kind: one warning, for it alone
    _periodic(system)
    new, _ = _warned(lambda: warn_conservation(system, "my-integrator"))
    assert len(new) == 1 and "periodic" in str(new[0].message)


def test_skipped_kinds_are_not_warned_and_can_warn_later(build):
    system = _isolated(build)
    system.addForce(mm.CMMotionRemover())
    caught, issues = _warned(lambda: warn_conservation(system, skip=("cmmotionremover",)))
    assert caught == [] and [k for k, _ in issues] == ["cmmotionremover"]
    assert not warn_once.seen("cmmotionremover")
    caught, _ = _warned(lambda: warn_conservation(system))
    assert len(caught) == 1


def test_an_integrator_on_such_a_system_warns_once(build):
    from openmm_symprk import SymplecticIntegrator

    system = _isolated(build)
    system.addForce(mm.CMMotionRemover())
    first, _ = _warned(lambda: SymplecticIntegrator(1 * unit.femtoseconds, "verlet", system=system))
    second, _ = _warned(lambda: SymplecticIntegrator(1 * unit.femtoseconds, "yoshida-4", system=system))
    assert len(first) == 1 and "CMMotionRemover" in str(first[0].message)
    assert second == []


def test_validate_system(build):
    with pytest.raises(TypeError, match="system must be an openmm.System, got str"):
        validate_system("system.xml", "test")
    system = _isolated(build)
    system.addForce(mm.CMMotionRemover())  # resets momentum, but does not make exact momentum wrong
    with pytest.warns(ConservationWarning):
        validate_system(system, "test", exact_momentum=True)
    for kind in ("periodic", "frozen", "customexternalforce"):
        system = _isolated(build)
        MODIFICATIONS[kind][0](system)
        with pytest.raises(ValueError, match="only correct for an isolated System.*Use exact_momentum=False"):
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                validate_system(system, "test", exact_momentum=True)
        validate_system(system, "test", exact_momentum=False)  # without exact momentum: a warning only


# -- what a run asked for: a production NVT box is not told about its CMMotionRemover and its box --------------------
@pytest.fixture(scope="module")
def standard_box():
    """ForceField.createSystem's defaults on a small TIP3P box: PME, HBonds, and the CMMotionRemover it adds."""
    import openmm.app as app

    ff = app.ForceField("amber14-all.xml", "amber14/tip3p.xml")
    mod = app.Modeller(app.Topology(), [])
    mod.addSolvent(ff, model="tip3p", boxSize=mm.Vec3(2.0, 2.0, 2.0) * unit.nanometer)
    system = ff.createSystem(mod.topology, nonbondedMethod=app.PME, nonbondedCutoff=0.9 * unit.nanometer,
                             constraints=app.HBonds)
    assert {k for k, _ in conservation_issues(system)} == {"cmmotionremover", "periodic"}
    return system


@pytest.mark.parametrize("backend", ["native", "custom"])
def test_a_standard_pme_box_in_nvt_builds_without_a_conservation_warning(standard_box, backend):
    from openmm_symprk import SymplecticIntegrator

    caught, _ = _warned(lambda: SymplecticIntegrator(2 * unit.femtoseconds, "verlet", system=standard_box,
                                                     backend=backend, temperature=300 * unit.kelvin))
    assert [str(w.message) for w in caught] == []


def test_exact_momentum_on_a_standard_pme_box_still_warns_and_refuses(standard_box):
    from openmm_symprk import SymplecticIntegrator

    def build():
        with pytest.raises(ValueError, match="only correct for an isolated System.*Use exact_momentum=False"):
            SymplecticIntegrator(2 * unit.femtoseconds, "verlet", system=standard_box, exact_momentum=True,
                                 temperature=300 * unit.kelvin)

    caught, _ = _warned(build)  # both kinds, as before: the user asked for conservation
    messages = " | ".join(str(w.message) for w in caught)
    assert len(caught) == 2 and "CMMotionRemover" in messages and "periodic boundary conditions" in messages


def test_an_nve_run_is_told_what_breaks_the_conservation_it_is_for(build, standard_box):
    """NVE of an isolated System: every kind, as before; NVE of a periodic box: what breaks its energy (a barostat),
    not its CMMotionRemover or its box; NVT: none of them."""
    system = _isolated(build)
    system.addForce(mm.CMMotionRemover())
    caught, _ = _warned(lambda: validate_system(system, "nve"))
    assert len(caught) == 1 and "CMMotionRemover" in str(caught[0].message)
    warn_once.reset()
    caught, _ = _warned(lambda: validate_system(system, "nvt", thermostat=True))
    assert caught == []
    box = copy.deepcopy(standard_box)
    caught, _ = _warned(lambda: validate_system(box, "nve"))
    assert caught == []
    box.addForce(mm.MonteCarloBarostat(1.0, 300.0))
    caught, _ = _warned(lambda: validate_system(box, "npt", thermostat=True))
    assert caught == []
    caught, _ = _warned(lambda: validate_system(box, "nve"))
    assert [str(w.message).split(":")[0] for w in caught] == ["nve"] and "MonteCarloBarostat" in str(caught[0].message)
