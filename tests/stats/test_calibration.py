"""How the package's drift error bar compares with the two it replaced, on series with a known slope.

Before openmm_symprk.stats, the bench (studies/bench/measure.drift_with_error: autocorrelation of the residuals
summed up to its first negative value, no test) and the equipartition study (studies/equipartition/stats.drift:
Sokal's automatic window, c = 5) estimated the standard error of an energy drift differently; both are kept here,
as they were, only to measure them.  ``python -m pytest -q -s tests/stats/test_calibration.py`` prints the
coverage table quoted in docs/production.md and docs/equipartition.md.
"""
import numpy as np
from scipy.signal import lfilter

from openmm_symprk.stats import drift

#: (phi, samples): AR(1) residuals with g = (1 + phi) / (1 - phi), from 50 samples through
#: 240 (a production bench run) and an equipartition run's ~830.
REGIMES = [(0.5, 50), (0.9, 50), (0.5, 240), (0.9, 240), (0.5, 800), (0.9, 800), (0.9, 4000)]
SERIES = 800


def old_bench(t, y):
    n = len(t)
    slope, intercept = np.polyfit(t, y, 1)
    r = y - (slope * t + intercept)
    var = float(np.sum(r * r) / (n - 2))
    g = 1.0
    c = np.correlate(r - r.mean(), r - r.mean(), "full")[n - 1:] / (np.arange(n, 0, -1) * r.var())
    for rho in c[1:n // 2]:
        if rho <= 0:
            break
        g += 2 * rho
    return slope, np.sqrt(var * g / float(np.sum((t - t.mean()) ** 2)))


def old_sokal(t, y, c=5.0):
    tc = t - t.mean()
    sxx = float(tc @ tc)
    slope = float(tc @ (y - y.mean())) / sxx
    d = y - y.mean() - slope * tc
    n = len(d)
    d = d - d.mean()
    f = np.fft.rfft(d, 2 * n)
    acf = np.fft.irfft(f * np.conj(f))[:n] / ((d @ d) / n * np.arange(n, 0, -1))
    g = 1.0
    for m in range(1, n // 2):
        g += 2.0 * acf[m]
        if m >= c * g:
            break
    return slope, np.sqrt(float(d @ d) / (n - 2) * max(1.0, g) / sxx)


def coverage(phi, n, series=SERIES, slope=0.3, seed=11):
    """Fraction of series with |slope_hat - slope| < 1.96 se, per estimator (new, old bench, old Sokal)."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) * 0.024
    hits = np.zeros(3)
    for _ in range(series):
        e = rng.normal(size=n)
        e[0] /= np.sqrt(1 - phi ** 2)
        y = slope * t + lfilter([1.0], [1.0, -phi], e)
        for k, f in enumerate((drift, old_bench, old_sokal)):
            a, se = f(t, y)
            hits[k] += abs(a - slope) < 1.96 * se
    return hits / series


def test_coverage_of_the_new_and_the_old_estimators():
    table = {reg: coverage(*reg) for reg in REGIMES}
    binomial = np.sqrt(0.95 * 0.05 / SERIES)
    print(f"\ncoverage of slope ± 1.96 se over {SERIES} AR(1) series per row (nominal 0.95, binomial SE {binomial:.3f})")
    print(f"{'phi':>4s} {'g':>5s} {'samples':>7s} {'new (pymbar)':>12s} {'old bench':>10s} {'old Sokal':>10s}")
    for (phi, n), (new, bench, sokal) in table.items():
        print(f"{phi:4.1f} {(1 + phi) / (1 - phi):5.1f} {n:7d} {new:12.3f} {bench:10.3f} {sokal:10.3f}")
    # with many effective samples the new error bar is calibrated
    assert abs(table[(0.9, 4000)][0] - 0.95) < 3 * binomial
    assert abs(table[(0.5, 800)][0] - 0.95) < 3 * binomial
    # the old bench estimator truncated like pymbar does: the same coverage within the noise
    for new, bench, _ in table.values():
        assert abs(new - bench) < 0.03
    # Sokal's window, with its shorter sums, covered less than the new estimator in every short-series regime
    for reg in [(0.5, 50), (0.9, 50), (0.9, 800)]:
        assert table[reg][2] < table[reg][0] - 0.02, reg
