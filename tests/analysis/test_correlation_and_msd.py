"""The FFT correlation and MSD against their O(n^2) definitions, and the MSD against MDAnalysis' EinsteinMSD."""
import numpy as np
import pytest

from openmm_symprk.analysis.correlation import origin_averaged_correlation
from openmm_symprk.analysis.diffusion import mean_squared_displacement


def test_fft_correlation_equals_the_double_loop():
    a = np.random.default_rng(1).normal(size=(57, 4, 3))
    c = origin_averaged_correlation(a, max_lag=56)
    for m in (0, 1, 7, 30, 56):
        direct = (a[:57 - m] * a[m:]).mean(axis=0)
        np.testing.assert_allclose(c[m], direct, rtol=1e-12, atol=1e-12)


def test_msd_equals_the_double_loop():
    r = np.cumsum(np.random.default_rng(2).normal(size=(80, 5, 3)), axis=0)
    msd = mean_squared_displacement(r, max_lag=79)
    for m in (0, 1, 13, 40, 79):
        direct = ((r[m:] - r[:80 - m]) ** 2).sum(axis=2).mean(axis=0)
        np.testing.assert_allclose(msd[m], direct, rtol=1e-10, atol=1e-10)


def test_msd_agrees_with_mdanalysis_einstein_msd():
    """The same numbers as MDAnalysis' EinsteinMSD (direct windowed algorithm) on a Universe built in memory."""
    mda = pytest.importorskip("MDAnalysis")
    from MDAnalysis.analysis.msd import EinsteinMSD
    from MDAnalysis.coordinates.memory import MemoryReader

    r = np.cumsum(np.random.default_rng(3).normal(scale=0.05, size=(60, 6, 3)), axis=0)  # nm
    u = mda.Universe.empty(6, trajectory=False)
    u.load_new((r * 10.0).astype(np.float32), format=MemoryReader)  # Angstrom
    ref = EinsteinMSD(u.atoms, msd_type="xyz", fft=False).run()
    ours = mean_squared_displacement(r, max_lag=59)
    np.testing.assert_allclose(ours.mean(axis=1) * 100.0, ref.results.timeseries, rtol=2e-5, atol=1e-6)


@pytest.mark.parametrize("bad", [0, 100])
def test_bad_max_lag_is_named(bad):
    with pytest.raises(ValueError, match="max_lag"):
        origin_averaged_correlation(np.zeros((10, 3)), max_lag=bad)
