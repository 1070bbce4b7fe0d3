"""One resolved description of a method (methods.resolved.resolve): what every runner takes."""
import dataclasses
import importlib
import math
from fractions import Fraction

import numpy as np
import pytest

import openmm_symprk
from openmm_symprk.methods import (PRKTableau, Splitting, SubstepFlag, SubstepKind, TableauError,
                                   UnknownMethodError, methods, resolve)
from openmm_symprk.methods.reference import henon_heiles_force, integrate
from openmm_symprk.methods.resolved import ConstraintSupportError, projected_drifts
from openmm_symprk.methods.respa import MTSError, evaluations_per_step, levels, respa
from openmm_symprk.methods.stability import stability_interval

ALL = list(methods)


def _old_projected(splitting):
    """The rule as the package wrote it before (Splitting.projected_drifts and both C++ kernels, in float64)."""
    out, previous = [], 0.0
    for i, (label, c) in enumerate(splitting.coefficients()):
        if label == "drift":
            if previous != 0.0 and abs(c) > abs(previous):
                out.append(i)
            previous = c
    return out


# -- the package layout ---------------------------------------------------------------------------------------------
def test_methods_is_the_subpackage():
    import openmm_symprk.methods.splitting as splitting_module

    assert openmm_symprk.methods is importlib.import_module("openmm_symprk.methods")
    assert openmm_symprk.methods.splitting is splitting_module
    assert openmm_symprk.catalogue is methods is openmm_symprk.methods.methods
    assert openmm_symprk.catalogue["leapfrog"].name == "verlet"
    assert openmm_symprk.resolve is resolve


# -- every catalogue method ---------------------------------------------------------------------------------------------
@pytest.mark.parametrize("name", ALL)
@pytest.mark.parametrize("constraints", [False, True])
def test_catalogue_methods_resolve_as_the_old_code_derived(name, constraints):
    m = methods[name]
    if constraints and not m.is_splitting:
        with pytest.raises(ConstraintSupportError, match=f"'{name}'.*cannot keep constraints"):
            resolve(name, constraints=True)
        return
    r = resolve(name, constraints=constraints)
    assert (r.name, r.entry, r.family, r.order, r.constrained_order, r.stability) == (
        m.name, m, m.family, m.order, m.constrained_order, m.stability)
    assert r.constraints is constraints and not r.levels
    assert r.tableau == m.tableau() and r.stages == m.tableau().stages
    if not m.is_splitting:
        assert r.form == ("explicit" if m.tableau().is_explicit else "implicit") and r.substeps == ()
        assert r.force_evals == m.force_evals
        return
    assert r.form == "splitting" and m.family in ("splitting", "composition")
    # the sequence as it runs: compositions over velocity Verlet (RATTLE) under constraints
    assert r.splitting == (m.constrained_splitting if constraints else m.splitting)
    assert [(s.label, s.coefficient) for s in r.substeps] == list(r.splitting.steps)
    # force evaluations: the catalogue's count, and the kicks that are not on cached forces
    assert r.force_evals == m.force_evals == sum(s.kind == SubstepKind.KICK and not s.forces_cached
                                                 for s in r.substeps)
    assert all(not s.forces_cached for s in r.substeps if s.kind == SubstepKind.DRIFT)
    # projections: exactly the drifts the old rule flagged, and none without constraints
    flagged = [i for i, s in enumerate(r.substeps) if s.project_before]
    assert flagged == (_old_projected(r.splitting) if constraints else [])
    assert all(s.flags == (SubstepFlag.PROJECT_BEFORE if s.project_before else 0)
               | (SubstepFlag.FORCES_CACHED if s.forces_cached else 0) for s in r.substeps)


def test_known_flags():
    verlet = resolve("verlet", constraints=True)
    assert [(s.label, float(s.coefficient), int(s.flags)) for s in verlet.substeps] == [
        ("kick", 0.5, SubstepFlag.FORCES_CACHED), ("drift", 1.0, 0), ("kick", 0.5, 0)]
    # pefrl: 0.775 after -0.066 and 0.179 after -0.066 are projected; 4 kicks, every one after a drift
    pefrl = resolve("pefrl", constraints=True)
    assert projected_drifts(pefrl.splitting) == [4, 8] == [i for i, s in enumerate(pefrl.substeps) if s.project_before]
    assert pefrl.force_evals == 4 and not any(s.forces_cached for s in pefrl.substeps)
    # yoshida-4 under constraints: only its middle drift (-1.70 after 1.35)
    y4 = resolve("yoshida-4", constraints=True)
    assert [float(s.coefficient) for s in y4.substeps if s.project_before] == pytest.approx([-1.7024143839193153])


def test_unknown_system_keeps_rattle_for_splittings_only():
    assert resolve("verlet", constraints=None).constraints is True
    assert resolve("gauss-2", constraints=None).constraints is False


# -- frozen, hashable, computed once ----------------------------------------------------------------------------------------
def test_resolved_is_frozen_and_hashable():
    a, b = resolve("yoshida-4", constraints=True), resolve("Yoshida_4", constraints=True)
    assert a == b and hash(a) == hash(b) and len({a, b, resolve("yoshida-4")}) == 2
    with pytest.raises(dataclasses.FrozenInstanceError):
        a.force_evals = 1
    with pytest.raises(dataclasses.FrozenInstanceError):
        a.substeps[0].project_before = True
    assert isinstance(a.substeps, tuple) and isinstance(a.evals_per_group, tuple)
    mts = resolve("verlet", constraints=True, groups=[(0, 1), (1, 4)])
    assert hash(mts) == hash(resolve("verlet", constraints=True, groups=[(0, 1), (1, 4)]))
    user = resolve(PRKTableau([[0.5]], [1], [[0.5]], [1], name="midpoint"))
    assert hash(user) == hash(resolve(PRKTableau([[0.5]], [1], [[0.5]], [1], name="midpoint")))


def test_resolving_a_resolved_method_gives_it_back():
    r = resolve("kahan-li-6", constraints=True)
    assert resolve(r, constraints=True) == r
    assert resolve(r, constraints=False) == resolve("kahan-li-6")


def test_tableau_derived_facts_are_computed_once(monkeypatch):
    calls = {"residual": 0, "to_splitting": 0}
    residual, to_splitting = PRKTableau.symplectic_residual_matrix, PRKTableau.to_splitting

    def counting_residual(self):
        calls["residual"] += 1
        return residual(self)

    def counting_to_splitting(self, tol=1e-14):
        calls["to_splitting"] += 1
        return to_splitting(self, tol)

    monkeypatch.setattr(PRKTableau, "symplectic_residual_matrix", counting_residual)
    monkeypatch.setattr(PRKTableau, "to_splitting", counting_to_splitting)
    tab = methods["gauss-2"]._make_tableau(np.float64)  # a fresh one (the catalogue caches its own)
    for _ in range(5):
        assert tab.is_symplectic and tab.residual_6 < 1e-14 and tab.summary()
        assert tab.explicit_order is None and not tab.is_explicit
        tab.check_symplectic()
        assert tab.splitting is None
    assert calls == {"residual": 1, "to_splitting": 1}
    for name in ("residual_6", "residual_7", "is_symplectic", "explicit_order", "splitting"):
        assert name in tab.__dict__, name
    # a resolution asks the tableau once more at most: its facts are kept
    resolve(tab)
    resolve(tab)
    assert calls == {"residual": 1, "to_splitting": 1}
    s = Splitting([("kick", "1/2"), ("drift", 1), ("kick", "1/2")])
    assert s.evaluating_kicks is s.evaluating_kicks and s.force_evaluations() == 1


def test_tableau_is_immutable():
    tab = PRKTableau([[0.5]], [1], [[0.5]], [1], name="midpoint")
    with pytest.raises(AttributeError, match="immutable"):
        tab.A = np.zeros((1, 1))
    with pytest.raises(ValueError, match="read-only"):
        tab.A[0, 0] = 1.0
    source = np.array([[0.5]])
    tab2 = PRKTableau(source, [1], [[0.5]], [1])
    source[0, 0] = 9.0  # the caller's array is copied
    assert tab2.A[0, 0] == 0.5 and tab2 == tab and hash(tab2) == hash(tab)
    assert tab != PRKTableau([[0.5]], [1], [[0.5]], [1], dtype=np.longdouble)


# -- user methods --------------------------------------------------------------------------------------------------------
def test_user_inputs():
    s = Splitting([("kick", "1/2"), ("drift", 1), ("kick", "1/2")])
    r = resolve(s, constraints=True, name="mine")
    assert (r.name, r.form, r.order, r.stability, r.entry) == ("mine", "splitting", None, None, None)
    assert r.splitting == methods["verlet"].splitting and r.force_evals == 1 and r.tableau.name == "mine"
    assert resolve(s).name == "user splitting"
    # a tableau in splitting form is a splitting (it runs with RATTLE); a general one is not
    tab = PRKTableau.from_splitting(methods["pefrl"].splitting, name="my pefrl")
    rt = resolve(tab, constraints=True)
    assert (rt.form, rt.name, rt.force_evals) == ("splitting", "my pefrl", 4)
    assert [i for i, st in enumerate(rt.substeps) if st.project_before] == [4, 8]
    gauss = methods["gauss-2"].tableau()
    assert resolve(PRKTableau(gauss.A, gauss.b, gauss.A_hat, gauss.b_hat)).form == "implicit"
    with pytest.raises(ConstraintSupportError, match="'user tableau'"):
        resolve(PRKTableau(gauss.A, gauss.b, gauss.A_hat, gauss.b_hat), constraints=True)


def test_bad_inputs():
    with pytest.raises(UnknownMethodError, match="'yoshida-4'"):
        resolve("yoshida-5")
    with pytest.raises(TypeError, match="expected a method name, a catalogue Method, a Splitting or a PRKTableau"):
        resolve(42)
    with pytest.raises(TableauError, match="'X1'"):
        resolve(Splitting([("X1", 1), ("drift", 1)]))
    with pytest.raises(ValueError, match="needs groups="):
        resolve("verlet", inner_method="pefrl")
    with pytest.raises(MTSError, match="general.*tableau"):
        resolve("gauss-2", groups=[(0, 1), (1, 2)])
    with pytest.raises(MTSError, match="general.*tableau"):
        resolve("verlet", constraints=True, groups=[(0, 1), (1, 2)], inner_method="gauss-2")
    with pytest.raises(MTSError, match="substeps 0"):
        resolve("verlet", groups=[(0, 1), (1, 0)])


# -- multiple time stepping --------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("constraints", [False, True])
def test_mts_matches_respa(constraints):
    r = resolve("yoshida-4", constraints=constraints, groups=[(1, 1), (0, 3)], inner_method="verlet")
    outer = methods["yoshida-4"].constrained_splitting if constraints else methods["yoshida-4"].splitting
    want = respa(levels([(1, 1), (0, 3)], outer, methods["verlet"].splitting))
    assert r.splitting == want and r.is_mts and r.groups == ((1, 1), (0, 3)) and r.inner_name == "verlet"
    assert r.evaluations == evaluations_per_step(want) == {(1,): 3, (0,): 9}
    assert r.force_evals == 12 and r.tableau is None and r.stability == methods["yoshida-4"].stability
    assert [s.group_mask for s in r.substeps if s.kind == SubstepKind.KICK][:2] == [1 << 1, 1 << 0]
    assert [i for i, s in enumerate(r.substeps) if s.project_before] == (_old_projected(want) if constraints else [])
    assert "groups 1 x1 (3 evaluations per step); groups 0 x3 (9 evaluations per step)" in r.describe_levels()


# -- the pure-numpy runners take it -------------------------------------------------------------------------------------------
def test_reference_and_stability_take_the_resolved_method():
    r = resolve("mclachlan-atela-4")
    q0, p0 = np.array([0.1, 0.3]), np.array([0.35, -0.1])
    assert np.array_equal(integrate(r, henon_heiles_force, q0, p0, 0.1, 20)[0],
                          integrate("mclachlan-atela-4", henon_heiles_force, q0, p0, 0.1, 20)[0])
    assert stability_interval(r) == pytest.approx(methods["mclachlan-atela-4"].stability, abs=1e-4)
    # long double tableaux come from the exact data
    assert r.tableau_in(np.longdouble).dtype == np.dtype(np.longdouble)
    assert r.tableau_in(np.longdouble) == methods["mclachlan-atela-4"].tableau(np.longdouble)
    with pytest.raises(TableauError, match="multiple-time-step"):
        resolve("verlet", groups=[(0, 1), (1, 2)]).tableau_in(np.float64)
    assert math.isinf(stability_interval(resolve(Splitting([("kick", Fraction(1, 2)), ("drift", 1), ("kick", "1/2")])),
                                         x_max=1.0))
