"""Error bars of the equipartition study against processes with known answers (pure numpy, milliseconds)."""
import numpy as np
import pytest

from openmm_symprk.studies.equipartition.stats import Estimate, agrees, combine, drift, inefficiency, series_stats


def _ar1(phi, n, rng):
    e = rng.normal(size=n)
    x = np.empty(n)
    x[0] = e[0] / np.sqrt(1 - phi ** 2)
    for i in range(1, n):
        x[i] = phi * x[i - 1] + e[i]
    return x


def test_white_noise_has_inefficiency_one():
    g = inefficiency(np.random.default_rng(1).normal(size=20000))
    assert 0.9 < g < 1.15


@pytest.mark.parametrize("phi", [0.5, 0.9])
def test_ar1_inefficiency_matches_theory(phi):
    """AR(1): g = (1 + phi) / (1 - phi) exactly (3 and 19)."""
    g = inefficiency(_ar1(phi, 200000, np.random.default_rng(2)))
    assert abs(g / ((1 + phi) / (1 - phi)) - 1) < 0.12


def test_standard_error_covers_the_truth_at_the_stated_rate():
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


def test_drift_recovers_a_slope_within_its_error():
    rng = np.random.default_rng(4)
    t = np.linspace(0, 20, 2000)
    inside = 0
    for _ in range(100):
        slope, se = drift(t, 0.3 * t + _ar1(0.7, len(t), rng))
        inside += abs(slope - 0.3) < 2 * se
    assert inside >= 88


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


def test_too_short_series_are_refused():
    with pytest.raises(ValueError, match="at least 2"):
        series_stats([1.0])
    with pytest.raises(ValueError, match="at least 3"):
        drift([0.0, 1.0], [0.0, 1.0])


def test_rows_are_compared_replica_by_replica():
    """Replicas share a large offset (each has its own total energy, the same for every row started from it):
    the paired difference resolves a row's 0.05 kJ/mol shift in the potential energy that the difference of
    the means (errors dominated by the offsets) cannot, and the match verdict follows it."""
    from openmm_symprk.studies.equipartition import presets
    from openmm_symprk.studies.equipartition.report import summarise

    rng = np.random.default_rng(7)
    cfg = presets.quick()
    cfg["models"] = {"spce": [["verlet", 0.5], ["verlet", 3.0], ["omelyan-2", 4.0]]}
    shift = {("verlet", 0.5): 0.0, ("verlet", 3.0): 0.05, ("omelyan-2", 4.0): 0.0}
    offsets = rng.normal(scale=0.3, size=8)  # per replica, kJ/mol per molecule
    t = np.arange(400) * 0.024
    runs = {}
    for (method, h), d in shift.items():
        reps = []
        for r, off in enumerate(offsets):
            pe = (-45.5 + off + d + rng.normal(scale=0.02, size=t.size)) * cfg["n_waters"]
            tt = 300 + rng.normal(scale=5, size=t.size)
            arrays = {"t": t, "T_trans": tt, "T_rot": tt + rng.normal(scale=5, size=t.size), "pe": pe,
                      "etot": np.full(t.size, -1e4) + rng.normal(scale=1.0, size=t.size)}
            reps.append((arrays, {"status": "ok", "replica": r}))
        runs[("spce", method, float(h))] = reps
    rows = {r["label"]: r for r in summarise(cfg, runs)["models"]["spce"]["rows"]}
    far, near = rows["verlet 3 fs"], rows["omelyan-2 4 fs"]
    assert far["vs_ref"]["pe"]["mean"] == pytest.approx(0.05, abs=0.005)
    ref = rows["verlet 0.5 fs"]
    assert far["vs_ref"]["pe"]["se"] < 0.005 and far["pe"]["se"] > 10 * far["vs_ref"]["pe"]["se"]
    assert agrees(Estimate(**{k: far["pe"][k] for k in ("mean", "se", "replicas", "se_within", "se_between")}),
                  Estimate(**{k: ref["pe"][k] for k in ("mean", "se", "replicas", "se_within", "se_between")}))
    assert not far["matches_ref"] and near["matches_ref"]
