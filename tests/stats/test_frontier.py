"""The frontier's arithmetic (openmm_symprk.stats.frontier) on synthetic families whose biases are known exactly:
b(h) = c h^p plus replica noise, paired with a reference replica by replica."""
import numpy as np
import pytest

from openmm_symprk.stats.frontier import (Family, bootstrap, compare, equal_accuracy_step, fit, fit_c, fits, frontier,
                                          replicas_for_interval, resample, strata)


def _family(name, c, steps, n=12, noise=0.01, order=2, seed=0, cost=1.0, shared=None, cap=None):
    """Biases c h^p + noise; ``shared`` (n,): a replica-to-replica term common to every row (the reference's own
    noise, which pairing carries into every row's bias)."""
    rng = np.random.default_rng(seed)
    steps = np.asarray(steps, dtype=float)
    b = c * steps[:, None] ** order + rng.normal(0, noise, (len(steps), n))
    if shared is not None:
        b = b + shared[None, :]
    return Family(name, tuple(steps), {"pe": b}, order=order, cost_per_step=cost, cap=cap)


def test_fit_recovers_c_and_weights_the_rows():
    f = _family("v", 0.01, [1, 2, 3], noise=1e-6)
    assert fit_c(f.steps, f.bias["pe"], 2) == pytest.approx(0.01, rel=1e-4)
    # weights: a noisy row counts for little (its SE is 100x larger)
    b = np.array(f.bias["pe"])
    b[2] = 0.5 + np.random.default_rng(3).normal(0, 1e-2, 12)  # a wild row at h = 3, but very noisy
    b[2] += 100 * (b[2] - b[2].mean())
    assert fit_c(f.steps, b, 2) == pytest.approx(0.01, rel=0.05)


def test_equal_accuracy_step_is_the_smallest_over_observables_and_capped():
    h = equal_accuracy_step({"pe": 0.01, "d": 0.04}, {"pe": 0.04, "d": 0.04}, 2, cap=10.0)
    assert h == pytest.approx(1.0)  # d binds: (0.04/0.04)^(1/2)
    assert equal_accuracy_step({"pe": 0.0}, {"pe": 0.04}, 2, cap=3.0) == 3.0  # no bias: the largest step
    assert equal_accuracy_step({"pe": -0.01}, {"pe": 0.04}, 2, cap=10.0) == pytest.approx(2.0)  # |c|


def test_two_families_compare_by_the_closed_form():
    """cost_B/cost_A = (s_B/s_A)(c_B/c_A)^(1/p) whatever the tolerance (THEORY section 7's arithmetic: Verlet c 0.0099,
    omelyan-2 c 0.0007 at two evaluations a step: 1.9x fewer evaluations)."""
    verlet = _family("verlet", 0.0099, [0.5, 1, 2], noise=1e-7, cost=1.0, cap=100)
    omelyan = _family("omelyan-2", 0.0007, [4, 5, 6, 7], noise=1e-7, cost=2.0, seed=1, cap=100)
    boot = bootstrap([verlet, omelyan], ["pe"], n_boot=200)
    for eps in (0.01, 0.03, 0.1):
        a = frontier(omelyan, {"pe": eps}, boot["omelyan-2"])
        b = frontier(verlet, {"pe": eps}, boot["verlet"])
        ratio, low, high = compare(a, b, 2.0, 1.0)
        assert ratio == pytest.approx((1.0 / 2.0) * (0.0099 / 0.0007) ** 0.5, rel=1e-3)  # 1.88
        assert low <= ratio <= high and high / low < 1.01  # noise-free: a tight interval
        assert a.limited_by == b.limited_by == "pe"


def test_a_family_without_measurable_bias_is_held_to_its_largest_step():
    flat = _family("flat", 0.0, [4, 6], noise=0.001)
    boot = bootstrap([flat], ["pe"], n_boot=200)
    point = frontier(flat, {"pe": 1.0}, boot["flat"])
    assert point.step == 6.0 and point.limited_by == "largest step" and point.safe_step == 6.0


def test_the_interval_covers_the_truth_about_as_often_as_it_says():
    """Calibration: 120 synthetic studies (12 replicas, noise comparable to the bias at the smaller steps, the
    reference's own noise shared by both families through the pairing); the 95 % interval of the ratio contains the
    true ratio in 85-100 % of them, and the 95 % safe step is below the true equal-accuracy step in >= 85 %."""
    p, eps = 2, 0.02
    true_ratio = (1.0 / 1.0) * (0.01 / 0.002) ** 0.5
    covered, safe_ok = 0, 0
    runs = 120
    for k in range(runs):
        shared = np.random.default_rng(1000 + k).normal(0, 0.01, 12)
        a = _family("a", 0.002, [2, 3, 4], noise=0.01, seed=2 * k, shared=shared, cap=50)
        b = _family("b", 0.01, [1, 1.5, 2], noise=0.01, seed=2 * k + 1, shared=shared, cap=50)
        boot = bootstrap([a, b], ["pe"], n_boot=300, seed=k)
        fa, fb = frontier(a, {"pe": eps}, boot["a"]), frontier(b, {"pe": eps}, boot["b"])
        _, low, high = compare(fa, fb, 1.0, 1.0)
        covered += low <= true_ratio <= high
        safe_ok += fa.safe_step <= (eps / 0.002) ** (1 / p)
    assert 0.85 * runs <= covered <= runs, covered
    assert safe_ok >= 0.85 * runs, safe_ok


def test_rows_with_fewer_replicas_keep_their_count_in_every_resample():
    """A family whose long-step rows ran 20 replicas and whose short-step row 12 (and a failed replica inside one
    row): the replicas are cut where a row's end, every resample gives the 12-replica row exactly 12 of its own, and
    one stratum draws what a plain resample draws."""
    b = np.random.default_rng(0).normal(0, 0.01, (3, 20))
    b[0, 12:] = np.nan
    b[1, 5] = np.nan  # a run that failed: its row still has 20 replicas
    f = Family("f", (1.0, 2.0, 3.0), {"pe": b})
    assert strata([f], ["pe"]) == [(0, 12), (12, 20)]
    picks = resample(strata([f], ["pe"]), 500, np.random.default_rng(1))
    assert picks.shape == (500, 20) and (np.sum(picks < 12, axis=1) == 12).all()
    assert ((picks[:, 12:] >= 12) & (picks[:, 12:] < 20)).all()
    whole = Family("g", (1.0, 2.0), {"pe": np.zeros((2, 12))})
    assert strata([whole], ["pe"]) == [(0, 12)]
    assert np.array_equal(resample([(0, 12)], 50, np.random.default_rng(2)),
                          np.random.default_rng(2).integers(0, 12, size=(50, 12)))
    # no resample leaves the short row without data
    boot = bootstrap([f], ["pe"], n_boot=300)
    assert np.isfinite(boot["f"]["pe"][:, 1]).all()


def test_bad_families_are_refused():
    with pytest.raises(ValueError, match="steps must be a non-empty list of positive steps"):
        Family("x", (), {"pe": np.zeros((0, 3))})
    with pytest.raises(ValueError, match="pe has 2 rows of biases for 3 steps"):
        Family("x", (1, 2, 3), {"pe": np.zeros((2, 3))})
    with pytest.raises(ValueError, match="at least two replicas"):
        fit_c([1, 2], np.full((2, 1), 0.1), 2)


def test_a_resample_without_data_gives_no_step():
    """A resample that left a row without data has no c (NaN): it says nothing of the step, so it is not counted as
    safe at the largest step (review of the frontier: it was the cap)."""
    h = equal_accuracy_step({"a": np.array([np.nan, 0.01])}, {"a": 0.04}, 2, 3.0)
    assert np.isnan(h[0]) and h[1] == pytest.approx(2.0)


def test_a_family_whose_bias_does_not_vanish_with_h_is_fitted_with_its_intercept():
    """A thermostat that changes the dynamics at any step (friction: diffusion 15 % slow) has a bias a + c h^2; fitted
    through the origin it would look small at small h.  With ``free`` the fit finds a, and where |a| exceeds the
    tolerance no step meets it: the family's cost is infinite, and a comparison against it has no finite bound."""
    rng = np.random.default_rng(5)
    steps = np.array([1.0, 2.0, 3.0])
    b = -0.15 + 0.004 * steps[:, None] ** 2 + rng.normal(0, 1e-4, (3, 12))
    friction = Family("langevin", tuple(steps), {"D": b}, free=("D",))
    a, c = fit(friction.steps, friction.bias["D"], 2, intercept=True)
    assert a == pytest.approx(-0.15, abs=1e-3) and c == pytest.approx(0.004, rel=0.02)
    boot = bootstrap([friction], ["D"], n_boot=100)
    assert boot["langevin"]["D"].shape == (100, 2) and np.allclose(boot["langevin"]["D"][:, 0], -0.15, atol=2e-3)
    assert frontier(friction, {"D": 0.05}, boot["langevin"]).step == 0.0  # |a| = 0.15 > 0.05 at every step
    # within the tolerance the bias leaves it where a + c h^2 crosses -eps or +eps: here +0.05 at h^2 = (0.05+0.15)/0.004
    assert float(equal_accuracy_step({"D": (-0.15, 0.004)}, {"D": 0.2}, 2, cap=100.0)) == pytest.approx(
        (0.35 / 0.004) ** 0.5)
    ours = _family("ours", 0.001, [2, 4, 6], noise=1e-4, cap=6)
    ours = Family("ours", ours.steps, {"D": ours.bias["pe"]}, cost_per_step=2.0)
    boot = bootstrap([ours, friction], ["D"], n_boot=100)
    ratio, low, high = compare(frontier(ours, {"D": 0.05}, boot["ours"]), frontier(friction, {"D": 0.05},
                                                                                   boot["langevin"]), 2.0, 1.0)
    assert ratio == np.inf and high == np.inf and low == np.inf


def test_families_of_one_cause_share_their_h_independent_part():
    """Two frictions of one Langevin integrator: a = kappa * friction (linear response), kappa shared.  The strong
    friction's clear effect fixes the weak one's, whose own rows are too noisy to: fitted alone its intercept is far
    off, jointly it is kappa / 10 within a few per cent of kappa."""
    rng = np.random.default_rng(7)
    steps = np.array([0.5, 1.0, 2.0, 3.0])
    kappa = -0.15
    strong = kappa * 1.0 + 0.004 * steps[:, None] ** 2 + rng.normal(0, 0.003, (4, 12))
    weak = kappa * 0.1 + 0.002 * steps[:, None] ** 2 + rng.normal(0, 0.05, (4, 12))
    a1 = Family("langevin 1/ps", tuple(steps), {"D": strong}, free=("D",), shared=("langevin", 1.0))
    a01 = Family("langevin 0.1/ps", tuple(steps), {"D": weak}, free=("D",), shared=("langevin", 0.1))
    got = fits([a1, a01], "D")
    assert got["langevin 1/ps"][0] == pytest.approx(kappa, abs=0.005)
    assert got["langevin 0.1/ps"][0] == pytest.approx(kappa * 0.1, abs=0.0005)
    assert got["langevin 0.1/ps"][1] == pytest.approx(0.002, abs=0.003)
    boot = bootstrap([a1, a01], ["D"], n_boot=200)
    assert np.allclose(boot["langevin 0.1/ps"]["D"][:, 0], 0.1 * boot["langevin 1/ps"]["D"][:, 0])
    point = frontier(a01, {"D": 0.05}, boot["langevin 0.1/ps"], point={"D": got["langevin 0.1/ps"]})
    assert point.step > 0  # |a| = 0.015 < 0.05: the weak friction meets the tolerance at small steps
    assert frontier(a1, {"D": 0.05}, boot["langevin 1/ps"], point={"D": got["langevin 1/ps"]}).step == 0.0


def test_the_replicas_an_interval_needs_follow_one_over_root_n():
    """Half-widths on a log scale shrink as 1/sqrt(n): an interval 1.0-2.0 around 1.2 (upper half-width ln(5/3))
    needs (ln(5/3) / ln 1.25)^2 = 11.7 times the replicas to fit within +-25 %; one already inside needs none more;
    an infinite end cannot be mended; bad input is named."""
    need = replicas_for_interval(12, 1.2, 1.0, 2.0)
    assert need == np.ceil(12 * (np.log(2.0 / 1.2) / np.log(1.25)) ** 2)
    assert replicas_for_interval(12, 1.2, 1.0, 1.4) == 12
    assert replicas_for_interval(12, 1.2, 0.8, 1.3) == np.ceil(12 * (np.log(1.2 / 0.8) / -np.log(0.75)) ** 2)
    assert replicas_for_interval(12, 1.2, 1.0, np.inf) == np.inf
    with pytest.raises(ValueError, match="within"):
        replicas_for_interval(12, 1.2, 1.0, 2.0, within=1.5)
