"""Every catalogue entry is measured: order on a nonlinear problem, stability interval, force evaluations.

Orders are measured in long double on the Henon-Heiles system (2 degrees of freedom, nonlinear forces),
by successive step halvings, so that a swapped kick/drift orientation or a wrong digit fails here."""
import math
from fractions import Fraction

import numpy as np
import pytest

from openmm_symprk import Splitting, UnknownMethodError, get_method, catalogue
from openmm_symprk.methods import catalogue as catalogue_module
from openmm_symprk.methods.catalogue import format_table
from openmm_symprk.methods.reference import measure_order
from openmm_symprk.methods.stability import stability_interval

ALL = list(catalogue)


def _steps(order):
    # step counts whose differences stay well above the long-double floor (~1e-17)
    return {8: (4, 8, 16, 32), 10: (4, 8, 16)}.get(order, (8, 16, 32, 64))


@pytest.mark.parametrize("name", ALL)
def test_measured_order_matches_catalogue(name):
    m = catalogue[name]
    orders, diffs = measure_order(m, steps=_steps(m.order))
    assert diffs[-1] > 1e-17, "differences reached round-off: the measurement is meaningless"
    assert abs(orders[-1] - m.order) < 0.3, f"{name}: measured order {orders} != catalogue {m.order}"


@pytest.mark.parametrize("name", ALL)
def test_stability_interval_matches_catalogue(name):
    m = catalogue[name]
    measured = stability_interval(m)
    if m.stability is None:
        pytest.fail(f"{name} has no stability interval in the catalogue (measured {measured:.4f})")
    if math.isinf(m.stability):
        assert math.isinf(measured)
    else:
        assert measured == pytest.approx(m.stability, rel=1e-3), f"{name}: measured {measured:.5f}"


@pytest.mark.parametrize("m", catalogue.splittings(), ids=lambda m: m.name)
def test_splitting_consistency_and_cost(m):
    s = m.splitting
    # consistency: kicks and drifts each sum to 1 (exact up to the 22 published digits)
    assert abs(float(s.total("kick") - 1)) < 1e-15 and abs(float(s.total("drift") - 1)) < 1e-15
    # the constrained sequence (compositions over velocity Verlet) costs what the catalogue's does
    assert m.constrained_splitting.force_evaluations() == m.force_evals == s.force_evaluations()
    if m.family == "composition":
        assert s.is_symmetric(tol=1e-21)
        assert m.constrained_splitting.is_symmetric(tol=1e-21)


def test_listed_force_evaluations_are_checked_against_the_coefficients():
    """The data files list each method's force evaluations per step; the catalogue derives the count from the
    sequence or tableau and refuses an entry that lists another."""
    raw = catalogue_module._load("splittings.toml") + catalogue_module._load("tableaux.toml")
    listed = {r["name"]: int(r["force_evals"]) for r in raw}
    assert listed == {name: m.force_evals for name, m in catalogue.items()}
    assert (listed["pefrl"], listed["yoshida-4"], listed["gauss-2"], listed["rk4"]) == (4, 3, 2, 4)
    for name in ("pefrl", "gauss-2"):
        wrong = [dict(r, force_evals=r["force_evals"] + 1) if r["name"] == name else r for r in raw]
        with pytest.raises(ValueError, match=f"{name}: force_evals = {listed[name] + 1} is listed, but its "
                                             f"(sequence|tableau) evaluates the forces {listed[name]} times"):
            catalogue_module._build(wrong)
    with pytest.raises(ValueError, match="unknown hamiltonian 'RKN'; one of separable, quadratic-kinetic"):
        catalogue_module._build([dict(raw[0], hamiltonian="RKN")])


def test_swapped_orientation_is_caught():
    """ODE.jl's McAte4 swaps kick and drift: on a nonlinear problem it is only third order."""
    m = catalogue["mclachlan-atela-4"]
    swapped = Splitting(("drift" if lab == "kick" else "kick", c) for lab, c in m.splitting)
    orders, _ = measure_order(swapped, steps=(8, 16, 32, 64))
    assert orders[-1] < 3.3


def test_wrong_digit_is_caught():
    m = catalogue["yoshida-6"]
    steps = list(m.splitting.steps)
    # a single wrong digit breaks consistency, which the exact sums catch ...
    label, c = steps[2]
    one_off = Splitting(steps[:2] + [(label, c + Fraction(1, 10 ** 9))] + steps[3:])
    assert abs(float(one_off.total(label) - 1)) > 1e-15
    # ... and a compensated error (sums still 1) breaks the order conditions, which the measurement catches
    label2, c2 = steps[4]
    assert label2 == label
    compensated = Splitting(steps[:2] + [(label, c + Fraction(1, 10 ** 5))] + steps[3:4]
                            + [(label, c2 - Fraction(1, 10 ** 5))] + steps[5:])
    assert compensated.total(label) == m.splitting.total(label)
    orders, _ = measure_order(compensated, steps=(8, 16, 32, 64, 128))
    assert orders[-1] < 3


def test_aliases_and_case():
    assert get_method("Velocity-Verlet").name == "verlet"
    assert get_method("forest_ruth").name == "forest-ruth-4-position"
    assert catalogue["McAte8"].name == "mclachlan-ss15-8"
    assert "leapfrog" in catalogue and "nonsense" not in catalogue


def test_unknown_name_suggests_close_names():
    with pytest.raises(UnknownMethodError) as info:
        get_method("yoshida-5")
    msg = str(info.value)
    assert "unknown method 'yoshida-5'" in msg and "'yoshida-4'" in msg and "Known methods" in msg



@pytest.mark.parametrize("name, openmm", [("langevin", "LangevinMiddleIntegrator"), ("BAOAB", "LangevinMiddleIntegrator"),
                                          ("langevin-middle", "LangevinMiddleIntegrator"),
                                          ("LangevinMiddleIntegrator", "LangevinMiddleIntegrator"),
                                          ("nose_hoover", "NoseHooverIntegrator"), ("brownian", "BrownianIntegrator"),
                                          ("svr", None)])
def test_a_thermostat_given_as_a_method_is_pointed_to_temperature(name, openmm):
    """A thermostat's name is not misspelt: the error says that the package's NVT is a method with temperature=, and
    names OpenMM's integrator of that kind, instead of suggesting close method names."""
    from openmm_symprk import SymplecticIntegrator

    with pytest.raises(UnknownMethodError) as info:
        SymplecticIntegrator(0.002, name)
    msg = str(info.value)
    assert msg.startswith(f"unknown method {name!r}: that is ") and "not a symplectic method" in msg
    assert "temperature=300*unit.kelvin" in msg and "Did you mean" not in msg and "Known methods" not in msg
    assert (f"use OpenMM's {openmm}" in msg) if openmm else "use OpenMM's" not in msg


def test_a_name_that_only_contains_a_thermostat_name_gets_suggestions():
    with pytest.raises(UnknownMethodError, match="Did you mean 'verlet'") as info:
        get_method("verlet-langevin")
    assert "temperature=" not in str(info.value)

def test_families_and_table():
    fams = {m.family for m in catalogue.values()}
    assert fams == {"splitting", "composition", "implicit", "reference"}
    table = format_table()
    for name in ALL:
        assert name in table
    assert not catalogue["rk4"].symplectic and catalogue["gauss-2"].symplectic
    # which Hamiltonians the order holds for: the SRKN/RKN splittings need a quadratic kinetic energy
    assert {m.hamiltonian for m in catalogue.values()} == {"separable", "quadratic-kinetic"}
    assert catalogue["blanes-moan-srkn6b-4"].hamiltonian == "quadratic-kinetic" == catalogue["mclachlan-sb3a4"].hamiltonian
    assert catalogue["blanes-moan-s6-4"].hamiltonian == "separable" == catalogue["gauss-2"].hamiltonian
    assert "hamiltonian" in table.splitlines()[0] and "quadratic-kinetic" in table


def test_narrow_instability_band_is_found():
    """sofroniou-spaletta-10 is unstable in a band 7.6e-4 wide near h*omega = pi, narrower than the scan
    grid; the interval ends at the band, not at the next wide instability (~5.97)."""
    from openmm_symprk.methods.stability import _stable

    tab = catalogue["sofroniou-spaletta-10"].tableau()
    assert not _stable(tab, np.array([3.1415]))[0]
    assert _stable(tab, np.array([3.1405, 3.1425])).all()  # stable on both sides of the band
    assert stability_interval("sofroniou-spaletta-10") == pytest.approx(3.14108, abs=1e-4)
