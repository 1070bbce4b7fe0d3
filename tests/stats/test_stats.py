"""The package's one statistics module against processes with known answers (numpy; pymbar's timeseries).

Calibration: on AR(1) noise plus a known slope, the drift's error bar covers the true slope at the stated rate
(95% for 1.96 standard errors, within the binomial error of the number of series), where the naive error bar
(independent samples) covers far less.
"""
import numpy as np
import pytest
from scipy.signal import lfilter

from openmm_symprk.stats import (Estimate, RunningLine, agrees, block_stats, combine, difference, drift, no_larger,
                                 paired, series_stats, statistical_inefficiency)


def _ar1(phi, n, rng):
    """x_i = phi x_{i-1} + e_i with unit-variance e, started in its stationary distribution; g = (1+phi)/(1-phi)."""
    e = rng.normal(size=n)
    e[0] /= np.sqrt(1 - phi ** 2)
    return lfilter([1.0], [1.0, -phi], e)


def _coverage(phi, n, series, seed, slope=0.3, z=1.96):
    rng = np.random.default_rng(seed)
    t = np.arange(n) * 0.01
    hits = naive = 0
    for _ in range(series):
        y = 5.0 + slope * t + _ar1(phi, n, rng)
        d = drift(t, y)
        hits += abs(d.slope - slope) < z * d.se
        naive += abs(d.slope - slope) < z * d.se / np.sqrt(d.g)
    return hits / series, naive / series


def test_white_noise_has_inefficiency_one():
    g = statistical_inefficiency(np.random.default_rng(1).normal(size=20000))
    assert 0.9 < g < 1.15


@pytest.mark.parametrize("phi", [0.5, 0.9])
def test_ar1_inefficiency_matches_theory(phi):
    """AR(1): g = (1 + phi) / (1 - phi) exactly (3 and 19)."""
    g = statistical_inefficiency(_ar1(phi, 200000, np.random.default_rng(2)))
    assert abs(g / ((1 + phi) / (1 - phi)) - 1) < 0.12


def test_constant_and_tiny_series_have_inefficiency_one():
    assert statistical_inefficiency(np.ones(100)) == 1.0
    assert statistical_inefficiency([1.0, 2.0]) == 1.0


@pytest.mark.parametrize("phi,n", [(0.5, 2000), (0.8, 4000)])
def test_drift_error_bar_covers_the_true_slope_95_percent_of_the_time(phi, n):
    """1000 series of AR(1) noise (g = 3 and 9) on a line of slope 0.3: |slope_hat - 0.3| < 1.96 se in 95% of
    them within 3 binomial standard errors (0.021), while the naive error bar covers 80% (g = 3) or 59% (g = 9)."""
    series = 1000
    covered, naive = _coverage(phi, n, series, seed=int(phi * 10))
    binomial = np.sqrt(0.95 * 0.05 / series)
    assert abs(covered - 0.95) < 3 * binomial, covered
    assert naive < 0.85, naive


def test_short_correlated_series_undercover():
    """The estimator's stated limit: with fewer than ~20 effective samples (50 samples, g = 19) the error bar
    covers about 70%, not 95% (the correlation time is itself poorly known); studies keep n/g large."""
    covered, _ = _coverage(0.9, 50, 400, seed=5)
    assert covered < 0.85


def test_drift_unpacks_as_slope_and_error_and_refuses_bad_input():
    slope, se = drift([0.0, 1.0, 2.0, 3.0], [0.0, 1.0, 2.0, 3.0])
    assert slope == pytest.approx(1.0) and se == pytest.approx(0.0, abs=1e-12)
    with pytest.raises(ValueError, match="at least 3"):
        drift([0.0, 1.0], [0.0, 1.0])
    with pytest.raises(ValueError, match="more than one time"):
        drift([1.0, 1.0, 1.0], [0.0, 1.0, 2.0])
    with pytest.raises(ValueError, match="one length"):
        drift([0.0, 1.0, 2.0], [0.0, 1.0])


def test_running_line_is_the_same_fit_with_constant_work():
    """The running fit gives drift()'s slope (and the uncorrelated error) at every sample, also for a long run far
    from the time origin where the naive running sums lose their digits."""
    rng = np.random.default_rng(6)
    t = 1e6 + np.arange(5000) * 0.002
    y = -3.2e5 + 0.05 * (t - t[0]) + rng.normal(scale=0.1, size=t.size)
    line = RunningLine()
    for i, (a, b) in enumerate(zip(t, y)):
        line.add(a, b)
        if i in (2, 99, 4999):
            d = drift(t[:i + 1], y[:i + 1])
            assert line.slope == pytest.approx(d.slope, rel=1e-6, abs=1e-9)
            assert line.se_uncorrelated == pytest.approx(d.se / np.sqrt(d.g), rel=1e-5)
    assert np.isnan(RunningLine().add(0.0, 1.0).slope)


def test_standard_error_of_a_mean_covers_the_truth_at_the_stated_rate():
    """Over 200 AR(1) series with mean 0, |mean| < 2 SE in about 95% of them (not 60%, as the naive SE gives)."""
    rng = np.random.default_rng(3)
    hits = naive = 0
    for _ in range(200):
        x = _ar1(0.8, 4000, rng)
        s = series_stats(x, dt=0.01)
        hits += abs(s.mean) < 2 * s.se
        naive += abs(s.mean) < 2 * x.std(ddof=1) / np.sqrt(len(x))
    assert 0.88 <= hits / 200 <= 0.995
    assert naive / 200 < 0.8
    assert abs(series_stats(_ar1(0.8, 100000, rng), dt=0.01).tau - 0.5 * 9 * 0.01) < 0.01


def test_block_error_covers_the_truth_at_the_stated_rate():
    """Over 400 AR(1) series (phi 0.8, g = 9) of 4000 samples, 20 blocks of 200 (>> the correlation time): |mean|
    < 2 SE in 94% of them (Student's t, 19 degrees of freedom), within the binomial error; the g that 1000 blocks
    of 200 imply on a long series is the theory's (1 + phi)/(1 - phi) = 9 within 15% (the block error of g: 4.5%;
    blocks of 200 bias it 2% low)."""
    rng = np.random.default_rng(5)
    hits = sum(abs(s.mean) < 2 * s.se for s in (block_stats(_ar1(0.8, 4000, rng), 20) for _ in range(400)))
    assert 0.90 <= hits / 400 <= 0.975
    s = block_stats(_ar1(0.8, 200000, rng), 1000, dt=0.01)
    assert abs(s.g - 9.0) < 1.35 and s.tau == pytest.approx(0.5 * s.g * 0.01) and s.n == 200000


def test_block_stats_refuses_too_few_blocks_or_samples():
    with pytest.raises(ValueError, match="n_blocks must be an integer >= 2, got 1"):
        block_stats(np.arange(10.0), 1)
    with pytest.raises(ValueError, match="n_blocks must be an integer >= 2, got 2.5"):
        block_stats(np.arange(10.0), 2.5)
    with pytest.raises(ValueError, match="8 blocks need at least 16 samples, got 10"):
        block_stats(np.arange(10.0), 8)
    s = block_stats([1.0, 2.0, 3.0, 4.0, 5.0], 2)  # the fifth sample counts in the mean, not in the blocks
    assert s.mean == 3.0 and s.se == pytest.approx(1.0)


def test_combine_takes_the_larger_error():
    e = combine([1.0, 1.0, 1.0, 1.0], [0.2, 0.2, 0.2, 0.2])
    assert e.se == pytest.approx(0.1) and e.se_between == 0.0
    e = combine([0.0, 2.0, 0.0, 2.0], [0.01] * 4)
    assert e.se == pytest.approx(np.std([0, 2, 0, 2], ddof=1) / 2) and e.mean == 1.0
    assert np.isnan(combine([1.0], [0.3]).se_between) and combine([1.0], [0.3]).se == 0.3
    with pytest.raises(ValueError, match="no replicas"):
        combine([], [])


def test_agreement_within_two_combined_errors():
    a = Estimate(0.0, 1.0, 4, 1.0, 1.0)
    assert agrees(a, Estimate(2.8, 1.0, 4, 1.0, 1.0))  # 2.8 < 2 * sqrt(2) = 2.83
    assert not agrees(a, Estimate(2.9, 1.0, 4, 1.0, 1.0))
    assert difference(Estimate(3.0, 0.3), Estimate(1.0, 0.4)).se == pytest.approx(0.5)
    assert no_larger(Estimate(-2.0, 0.1), Estimate(1.9, 0.0))  # magnitudes: 2.0 <= 1.9 + 2 * 0.1
    assert not no_larger(Estimate(2.5, 0.1), Estimate(-1.9, 0.1))


def test_paired_difference_cancels_what_replicas_share():
    """Two rows from the same replica states: a shared offset per replica cancels in the paired difference."""
    rng = np.random.default_rng(8)
    offsets = rng.normal(scale=1.0, size=6)
    ref = {r: (off, 0.01) for r, off in enumerate(offsets)}
    row = {r: (off + 0.05, 0.01) for r, off in enumerate(offsets)}
    row[99] = (10.0, 0.01)  # a replica the reference lacks is left out
    d = paired(row, ref)
    assert d.mean == pytest.approx(0.05) and d.se < 0.01 and d.replicas == 6
    assert not agrees(d, Estimate(0.0, 0.0))
    assert paired({1: (0.0, 1.0)}, {2: (0.0, 1.0)}) is None


def test_pymbar_is_imported_quietly(capfd):
    import subprocess
    import sys

    out = subprocess.run([sys.executable, "-c", "from openmm_symprk.stats import statistical_inefficiency as g; "
                          "import numpy as np; print(round(g(np.sin(np.arange(100) / 5)), 3) > 1)"],
                         capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "True" and out.stderr == "", out.stderr


def test_the_end_of_a_transient_is_found():
    """An AR(1) series that starts 20 units off and relaxes over ~50 samples: the equilibrated part starts after
    the transient, well before the end; a stationary series is equilibrated from its start."""
    from openmm_symprk.stats import equilibrated_from

    rng = np.random.default_rng(12)
    x = _ar1(0.5, 3000, rng) + 20.0 * np.exp(-np.arange(3000) / 50.0)
    t0 = equilibrated_from(x)
    assert 100 <= t0 <= 600
    assert equilibrated_from(_ar1(0.5, 3000, rng)) < 100
    assert equilibrated_from(np.ones(50)) == 0 and equilibrated_from([1.0, 2.0]) == 0
    d = drift(np.arange(3000.0), _ar1(0.5, 3000, rng))
    assert 600 < d.n_eff < 1500  # n / g with g = 3
