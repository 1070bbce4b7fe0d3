"""g(r) under periodic boundaries: an ideal gas gives g = 1 within its noise; a simple cubic lattice with small
thermal displacements has its first peak at the lattice constant with the height its 6 neighbours give."""
import numpy as np
import pytest

from openmm_symprk.analysis.structure import first_peak, radial_distribution


def test_ideal_gas_gives_one_within_the_counting_noise():
    rng = np.random.default_rng(31)
    box = np.array([3.0, 3.5, 4.0])
    x = rng.uniform(size=(40, 150, 3)) * box
    rdf = radial_distribution(x, box, r_max=1.5, dr=0.05, n_blocks=8)
    # expected pair count per bin: N(N-1)/2 * shell / V per frame; Poisson noise of g = 1/sqrt(count)
    shell = 4 * np.pi * ((rdf.r + 0.025) ** 3 - (rdf.r - 0.025) ** 3) / 3
    sigma = 1.0 / np.sqrt(40 * 150 * 149 / 2 * shell / np.prod(box))
    z = (rdf.g - 1.0) / sigma
    assert np.abs(z).max() < 4.5
    assert abs(z.mean()) * np.sqrt(len(z)) < 4  # no overall offset (the N - 1 normalisation)
    # the block errors estimate the same noise (within 40% on average over bins)
    assert 0.6 < np.sqrt(np.mean(rdf.se[5:] ** 2 / sigma[5:] ** 2)) < 1.4


def test_simple_cubic_lattice_first_peak_at_the_lattice_constant():
    """6 x 6 x 6 lattice, a = 0.3 nm, Gaussian displacements sigma = 0.006 nm per coordinate: the nearest
    neighbours' distances spread by sqrt(2) sigma, so g peaks at a with height
    (V/N) 6 / (4 pi a^2 sqrt(2 pi) sqrt(2) sigma) * N / (N - 1)."""
    rng = np.random.default_rng(32)
    a, n, s = 0.3, 6, 0.006
    grid = np.stack(np.meshgrid(*[np.arange(n)] * 3, indexing="ij"), -1).reshape(-1, 3) * a
    x = grid + rng.normal(scale=s, size=(200, n ** 3, 3))
    box = np.full(3, n * a)
    rdf = radial_distribution(x, box, r_max=0.9, dr=0.002, n_blocks=8)
    peak = first_peak(rdf, r_min=0.1)
    N = n ** 3
    height = a ** 3 * 6 / (4 * np.pi * a ** 2 * np.sqrt(2 * np.pi) * np.sqrt(2) * s) * N / (N - 1)
    assert abs(peak.r - a) < 3 * peak.r_se + 1e-4 and peak.r_se < 1e-3  # a fraction of a 2-pm bin
    assert abs(peak.height - height) < 3 * peak.height_se + 0.01 * height and peak.height_se < 0.02 * height
    assert rdf.g[(rdf.r > 0.05) & (rdf.r < 0.24)].max() == 0.0  # nothing closer than the neighbours
    # the second shell (12 neighbours at sqrt(2) a) is as high: "first" is the first run of g > 1, not the highest
    second = first_peak(rdf, r_min=0.36)
    assert second.r == pytest.approx(np.sqrt(2) * a, abs=1e-3) and second.height > 0.9 * peak.height


def test_parabola_refines_the_peak_between_bins():
    """A Gaussian peak centred between bin centres is found at its centre, closer than half a bin."""
    from openmm_symprk.analysis.structure import Rdf

    r = np.arange(0.0025, 1.0, 0.005)
    g = 1 + 2 * np.exp(-0.5 * ((r - 0.2817) / 0.02) ** 2)
    peak = first_peak(Rdf(r, g, np.zeros_like(r), g[None], 0.005))
    assert abs(peak.r - 0.2817) < 2e-4 < abs(r[np.argmax(g)] - 0.2817)
    assert peak.height == pytest.approx(3.0, abs=0.005)


def test_r_max_beyond_half_the_box_is_refused():
    with pytest.raises(ValueError, match="half the shortest box edge"):
        radial_distribution(np.zeros((1, 4, 3)), [2.0, 2.0, 1.0], r_max=0.8)


def test_g_equals_mdanalysis_interrdf():
    """The same numbers as MDAnalysis' InterRDF of a group with itself (self pairs excluded), Universe in memory."""
    mda = pytest.importorskip("MDAnalysis")
    from MDAnalysis.analysis.rdf import InterRDF
    from MDAnalysis.coordinates.memory import MemoryReader

    rng = np.random.default_rng(33)
    box, n = np.array([2.0, 2.2, 2.4]), 60
    x = rng.uniform(size=(10, n, 3)) * box
    u = mda.Universe.empty(n, trajectory=False)
    dims = np.tile(np.r_[box * 10, 90, 90, 90], (10, 1))  # Angstrom
    u.load_new((x * 10).astype(np.float32), format=MemoryReader, dimensions=dims)
    ref = InterRDF(u.atoms, u.atoms, nbins=50, range=(0.0, 10.0), exclusion_block=(1, 1)).run()
    ours = radial_distribution(x, box, r_max=1.0, dr=0.02, n_blocks=2)
    np.testing.assert_allclose(ours.r, ref.results.bins / 10, atol=1e-12)
    np.testing.assert_allclose(ours.g, ref.results.rdf, atol=1e-6)
