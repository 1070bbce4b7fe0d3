"""Extrapolation to h -> 0 by a + b h^2: exact on exact data, unbiased with honest errors on noisy data."""
import numpy as np
import pytest

from openmm_symprk.studies.fidelity.extrapolation import extrapolate_h2

H = np.array([0.5, 1.0, 2.0, 3.0])  # fs, the Verlet rows


def test_exact_values_give_a_and_b_exactly():
    fit = extrapolate_h2(H, 2.4 - 0.03 * H ** 2, [0.01, 0.02, 0.02, 0.05])
    assert fit.a == pytest.approx(2.4, abs=1e-12) and fit.b == pytest.approx(-0.03, abs=1e-12)
    assert fit.chi2_red == pytest.approx(0.0, abs=1e-20) and fit.dof == 2
    assert fit.at(2.0) == pytest.approx(2.4 - 0.12)


def test_two_points_by_hand():
    """y(1) = 3 +- 1, y(2) = 6 +- 1: b = 1, a = 2; var(a) = (h2^4 + h1^4)/(h2^2 - h1^2)^2 = 17/9."""
    fit = extrapolate_h2([1.0, 2.0], [3.0, 6.0], [1.0, 1.0])
    assert (fit.a, fit.b) == (pytest.approx(2.0), pytest.approx(1.0))
    assert fit.a_se == pytest.approx(np.sqrt(17 / 9)) and np.isnan(fit.chi2_red)


def test_noisy_values_recover_a_within_the_stated_error_at_the_stated_rate():
    """2000 synthetic studies with se growing with h: a within 1 a_se in ~68% of them, within 2 in ~95%, and
    the weighted fit is unbiased; chi2_red averages 1."""
    rng = np.random.default_rng(41)
    se = np.array([0.02, 0.02, 0.03, 0.05])
    fits = [extrapolate_h2(H, 2.4 + 0.05 * H ** 2 + rng.normal(scale=se), se) for _ in range(2000)]
    z = np.array([(f.a - 2.4) / f.a_se for f in fits])
    assert 0.64 < np.mean(np.abs(z) < 1) < 0.72
    assert 0.93 < np.mean(np.abs(z) < 2) < 0.97
    assert abs(z.mean()) < 0.1
    assert np.mean([f.b for f in fits]) == pytest.approx(0.05, abs=0.002)
    assert np.mean([f.chi2_red for f in fits]) == pytest.approx(1.0, abs=0.08)


def test_a_cubic_term_shows_in_chi2():
    fit = extrapolate_h2(H, 1.0 + 0.2 * H ** 3, np.full(4, 0.01))
    assert fit.chi2_red > 100


@pytest.mark.parametrize("h, y, se, match", [
    ([1.0, 1.0], [1.0, 2.0], [0.1, 0.1], "2 distinct step sizes"),
    ([1.0, 2.0], [1.0, 2.0], [0.1, 0.0], "standard error"),
    ([1.0, 2.0], [1.0, 2.0, 3.0], [0.1, 0.1], "one length"),
])
def test_bad_input_is_named(h, y, se, match):
    with pytest.raises(ValueError, match=match):
        extrapolate_h2(h, y, se)
