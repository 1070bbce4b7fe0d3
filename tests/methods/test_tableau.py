"""PRKTableau: validation, Reich's conditions, explicitness, conversions and composition (pure numpy)."""
from fractions import Fraction

import numpy as np
import pytest

from openmm_symprk import PRKTableau, Splitting, TableauError, compose, catalogue
from openmm_symprk.methods.reference import henon_heiles_force, prk_step, splitting_step

LOBATTO_IIIA = [["0", "0", "0"], ["5/24", "1/3", "-1/24"], ["1/6", "2/3", "1/6"]]
B3 = ["1/6", "2/3", "1/6"]


def test_bad_shapes_are_named():
    with pytest.raises(TableauError, match=r"A_hat has shape \(2, 2\).*shape \(3, 3\)"):
        PRKTableau(LOBATTO_IIIA, B3, [[0, 0], [0, 0]], B3)
    with pytest.raises(TableauError, match="b must be a non-empty vector"):
        PRKTableau([[0]], [], [[0]], [])


def test_non_finite_and_non_numeric_entries_rejected():
    with pytest.raises(TableauError, match="A_hat.*not finite"):
        PRKTableau([[0.0]], [1.0], [[float("nan")]], [1.0])
    with pytest.raises((TableauError, ValueError), match="not a number|abc"):
        PRKTableau([["abc"]], ["1"], [["0"]], ["1"])


def test_inconsistent_weights_rejected_with_value():
    with pytest.raises(TableauError, match=r"b sum to 0\.9.*sum\(b\) = 1"):
        PRKTableau([[0, 0], [0.5, 0]], [0.4, 0.5], [[0, 0], [0.5, 0]], [0.5, 0.5])


def test_reich_residuals_exact_values():
    iiia_iiib = catalogue["lobatto-iiia-iiib-3"].tableau()
    assert iiia_iiib.residual_6 < 1e-15 and iiia_iiib.residual_7 == 0.0
    assert iiia_iiib.is_symplectic_general
    # Lobatto IIIA paired with itself: the residual of (6) is 1/36 (the catalogue's reference value)
    bad = PRKTableau(LOBATTO_IIIA, B3, LOBATTO_IIIA, B3)
    assert bad.residual_6 == pytest.approx(1 / 36, rel=1e-14)
    assert not bad.is_symplectic
    rk4 = catalogue["rk4"].tableau()
    assert rk4.residual_6 > 0.1 and rk4.residual_7 == 0.0
    gauss = catalogue["gauss-2"].tableau()
    assert gauss.residual_6 < 1e-15


def test_splittings_satisfy_6_but_not_7():
    for m in catalogue.splittings():
        tab = m.tableau()
        assert tab.residual_6 == 0.0, m.name
        assert tab.is_explicit
    assert catalogue["yoshida-4"].tableau().residual_7 > 1.0  # b != b_hat is allowed for separable H


def test_check_symplectic_message_names_residual():
    bad = PRKTableau(LOBATTO_IIIA, B3, LOBATTO_IIIA, B3, name="iiia-iiia")
    with pytest.raises(TableauError, match=r"iiia-iiia is not symplectic.*2\.778e-02.*allow_nonsymplectic"):
        bad.check_symplectic()
    bad.check_symplectic(allow_nonsymplectic=True)


def test_explicitness():
    assert catalogue["rk4"].tableau().explicit_order == "q-first"
    assert catalogue["gauss-2"].tableau().explicit_order is None
    assert catalogue["lobatto-iiia-iiib-3"].tableau().explicit_order is None
    mirror = PRKTableau([[0.5, 0], [0.5, 0.5]], [0.5, 0.5], [[0, 0], [1, 0]], [0.5, 0.5])
    assert mirror.explicit_order == "p-first"


def test_splitting_tableau_round_trip():
    for m in catalogue.splittings():
        back = m.tableau().to_splitting()
        assert back.labels == m.splitting.labels, m.name
        assert max(abs(float(a[1] - b[1])) for a, b in zip(back, m.splitting)) < 1e-16
    with pytest.raises(TableauError, match="not a kick/drift splitting"):
        catalogue["rk4"].tableau().to_splitting()


def test_tableau_form_gives_same_step_as_sequence():
    q0, p0 = np.array([0.1, 0.3]), np.array([0.35, -0.1])
    for name in ("verlet", "position-verlet", "pefrl", "mclachlan-atela-4", "yoshida-6"):
        m = catalogue[name]
        qa, pa = splitting_step(m.splitting, henon_heiles_force, q0, p0, 0.1)
        qb, pb = prk_step(m.tableau(), henon_heiles_force, q0, p0, 0.1)
        assert np.max(np.abs(np.r_[qa - qb, pa - pb])) < 1e-15, name


def test_tableau_composition_matches_splitting_composition():
    w = catalogue["yoshida-4"].weights
    verlet = catalogue["verlet"]
    comp_tab = verlet.tableau().compose(w)
    comp_split = compose(verlet.splitting, w)
    assert comp_tab.residual_6 < 1e-15  # composition of symplectic steps is symplectic
    q0, p0 = np.array([0.1, 0.3]), np.array([0.35, -0.1])
    qa, pa = prk_step(comp_tab, henon_heiles_force, q0, p0, 0.2)
    qb, pb = splitting_step(comp_split, henon_heiles_force, q0, p0, 0.2)
    assert np.max(np.abs(np.r_[qa - qb, pa - pb])) < 1e-15
    with pytest.raises(TableauError, match="sum to 1"):
        verlet.tableau().compose([0.5, 0.4])


def test_splitting_merges_exactly_and_validates():
    s = Splitting([("kick", "1/4"), ("kick", "1/4"), ("drift", 1), ("drift", 0), ("kick", Fraction(1, 2))])
    assert s.steps == (("kick", Fraction(1, 2)), ("drift", Fraction(1)), ("kick", Fraction(1, 2)))
    assert s.force_evaluations() == 1 and s.is_symmetric()
    with pytest.raises(ValueError, match="'x' is not a number"):
        Splitting([("kick", "x")])
    with pytest.raises(ValueError, match="sum to 1"):
        compose(s, ["0.5", "0.6"])
    with pytest.raises(TableauError, match=r"only 'kick' and 'drift'.*\['X1'\]"):
        PRKTableau.from_splitting(Splitting([("X1", 1), ("kick", 1)]))
