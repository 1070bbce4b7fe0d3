"""The steps each method was measured to run (systems/data/step_limits.toml) and the one-time warning when an
integrator is built beyond them for a System of the kind measured."""
import glob
import json
import os
import re
import warnings

import openmm as mm
import openmm.app as app
import openmm.unit as unit
import pytest

from openmm_symprk import SymplecticIntegrator, plugin
from openmm_symprk.systems.hydrogens import hydrogen_facts
from openmm_symprk.systems.scenes import morse_molecule, openmm_data, water_box, water_cluster
from openmm_symprk.systems.step_limits import (STEP_LIMITS, SYSTEMS, StepLimitWarning, step_limit_warning,
                                               system_kinds)

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
BACKENDS = ["custom", pytest.param("native", marks=pytest.mark.skipif(
    not plugin.available(), reason=f"native plugin unavailable: {plugin.unavailable_reason()}"))]


def test_the_rigid_water_rows_are_the_committed_runs():
    """Every rigid-water row, derived again from the fidelity study's committed runs of SPC/E: the largest step at which
    every run of the method was "ok", the smallest at which every run was "unstable at step N", and the runs there
    (at least the number the table quotes)."""
    runs: dict = {}
    for path in glob.glob(os.path.join(REPO, "docs", "data", "fidelity", "*spce", "runs", "*.json")):
        with open(path) as fh:
            run = json.load(fh)
        m = re.match(r"(\S+) (\d+(?:\.\d+)?) fs( |$)", run["row"])
        if m:
            runs.setdefault((m.group(1), float(m.group(2))), []).append(run["status"])
    if not runs:
        pytest.skip("the fidelity study's runs are not in this checkout")
    derived = {}
    for (method, h), statuses in runs.items():
        ok = all(s == "ok" for s in statuses)
        blew = all(s.startswith("unstable at step") for s in statuses)
        assert ok or blew, (method, h, statuses)  # no step where some runs blew up and others did not
        row = derived.setdefault(method, {"stable": None, "unstable": None, "runs": {}})
        if ok and (row["stable"] is None or h > row["stable"]):
            row["stable"] = h
        if blew and (row["unstable"] is None or h < row["unstable"]):
            row["unstable"] = h
        row["runs"][h] = len(statuses)
    table = {limit.method: limit for limit in STEP_LIMITS if limit.system == "rigid-water"}
    # every method of the package the study ran (OpenMM's integrators are not the package's to warn about)
    assert set(table) == set(derived) - {"langevin", "openmm-verlet", "nose-hoover"}, set(derived)
    for method, limit in table.items():
        row = derived[method]
        assert (limit.stable_fs, limit.unstable_fs) == (row["stable"], row["unstable"]), method
        # the runs the table quotes are committed (a measurement that adds replicas adds to them)
        assert limit.runs <= row["runs"][limit.unstable_fs or limit.stable_fs], method


@pytest.fixture(scope="module")
def spce_box():
    return water_box("spce", n_waters=216)[0]


@pytest.fixture(scope="module")
def villin():
    """The solute of OpenMM's test.pdb in its periodic box (the water left out: it is not what is tested here) with
    HBonds, without and with hydrogen mass repartitioning to 1.5 Da."""
    pdb = app.PDBFile(openmm_data("test.pdb"))
    mod = app.Modeller(pdb.topology, pdb.positions)
    mod.delete([r for r in mod.topology.residues() if r.name == "HOH" or len(list(r.atoms())) == 1])
    ff = app.ForceField("amber14-all.xml")
    options = dict(nonbondedMethod=app.CutoffPeriodic, constraints=app.HBonds)
    return (ff.createSystem(mod.topology, **options),
            ff.createSystem(mod.topology, hydrogenMass=1.5 * unit.amu, **options))


def _built(system, method, step_fs, backend="custom", **options):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        SymplecticIntegrator(step_fs * unit.femtoseconds, method, system=system, backend=backend, **options)
    return [str(w.message) for w in caught if issubclass(w.category, StepLimitWarning)]


def test_the_kinds_of_system(spce_box, villin):
    assert system_kinds(spce_box) == ("rigid-water",)
    assert system_kinds(villin[0]) == ("protein",) and system_kinds(villin[1]) == ("protein-hmr",)
    assert system_kinds(morse_molecule().system) == ()


@pytest.mark.parametrize("backend", BACKENDS)
def test_yoshida_4_at_5_fs_on_rigid_water_warns_once_with_the_measurement(spce_box, backend):
    first = _built(spce_box, "yoshida-4", 5, backend, temperature=300 * unit.kelvin)
    assert len(first) == 1, first
    msg = first[0]
    assert "yoshida-4 blew up at 5 fs on every one of its 12 runs of 216 rigid SPC/E waters" in msg
    assert "(docs/fidelity.md)" in msg and "use at most 4 fs with yoshida-4" in msg
    assert _built(spce_box, "yoshida-4", 6, backend) == []  # once per process
    assert _built(spce_box, "yoshida-4", 4, backend) == []


def test_a_step_within_the_measurements_is_silent(spce_box, villin):
    for method, step in (("omelyan-2", 7), ("predescu-3", 12), ("verlet", 4), ("kahan-li-8", 20)):
        assert step_limit_warning(spce_box, method, step) == (), method
    assert _built(villin[0], "verlet", 2) == [] and _built(villin[1], "verlet", 4) == []


def test_a_protein_without_hmr_at_4_fs_is_told_what_was_measured(villin):
    (msg,) = _built(villin[0], "verlet", 4)
    assert "verlet was measured stable up to 2 fs, and not beyond, in 1 run of solvated villin" in msg
    assert "without hydrogen mass repartitioning (docs/production.md)" in msg
    (msg,) = _built(villin[1], "omelyan-2", 6)
    assert "omelyan-2 blew up at 6 fs on its run of solvated villin" in msg and "repartitioning to 1.5 Da" in msg


def test_no_warning_where_the_measurements_do_not_apply():
    """A System without rigid water or constrained hydrogens (a Morse molecule), or not periodic (a cluster of rigid
    waters in vacuum, whose steps the liquid's do not limit), is not of the kinds measured."""
    assert _built(morse_molecule().system, "yoshida-4", 5) == []
    cluster = water_cluster(8, minimize=False).system
    assert hydrogen_facts(cluster).rigid_waters == 8 and system_kinds(cluster) == ()
    assert _built(cluster, "yoshida-4", 5) == []


def test_every_row_names_a_known_system_and_method():
    from openmm_symprk.methods.catalogue import methods

    for limit in STEP_LIMITS:
        assert limit.system in SYSTEMS and limit.method in methods and limit.runs >= 1
        if limit.stable_fs is not None and limit.unstable_fs is not None:
            assert limit.stable_fs < limit.unstable_fs
