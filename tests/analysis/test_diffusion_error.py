"""D's standard error against the scatter of D between independent pieces of a known random walk whose walkers
move together, as a liquid's molecules do: many Brownian walkers whose diffusion coefficient is one shared,
fluctuating mobility D(t) = D0 exp(a x(t) - a^2 / 2), x an Ornstein-Uhlenbeck process of unit variance and
correlation time tau (so <D(t)> = D0 exactly, and every walker's long-time D is D0).  With a = 0.5 and tau = 0.1
ps the molecules' scatter understates D's error 2.3-2.4x, as it did in 216 SPC/E waters (2.5x over 4-ps pieces,
2-2.6x over 20-ps pieces of one Langevin run: see openmm_symprk.analysis.diffusion)."""
import numpy as np
import pytest

mda = pytest.importorskip("MDAnalysis")

from openmm_symprk.analysis.diffusion import block_error, self_diffusion  # noqa: E402
from openmm_symprk.analysis.universe import SelfDiffusion  # noqa: E402

pytestmark = [pytest.mark.filterwarnings("ignore::DeprecationWarning")]

D0 = 2.3e-3  # nm^2/ps: 2.3e-5 cm^2/s, water's
N_WALKERS, N_PIECES, FRAMES = 64, 80, 200


def _walk(rng, n_frames, n, dt, a=0.5, tau=0.1):
    """Centres (n_frames, n, 3) nm of ``n`` walkers sharing the mobility D0 exp(a x(t) - a^2/2)."""
    c = np.exp(-dt / tau)
    x = np.empty(n_frames - 1)
    x[0] = rng.normal()
    kicks = rng.normal(size=n_frames - 1) * np.sqrt(1 - c * c)
    for k in range(1, n_frames - 1):
        x[k] = c * x[k - 1] + kicks[k]
    d = D0 * np.exp(a * x - a * a / 2)
    steps = rng.normal(size=(n_frames - 1, n, 3)) * np.sqrt(2 * d * dt)[:, None, None]
    return np.concatenate([np.zeros((1, n, 3)), np.cumsum(steps, axis=0)]) + rng.uniform(0, 3, (n, 3))


def _waters(r, dt):
    """A Universe of rigid waters (O-H 1 A, H-H 1.633 A) whose centres of mass follow ``r`` (nm), no box."""
    n = r.shape[1]
    site = np.array([[0.0, 0.0, 0.0], [0.8165, 0.5774, 0.0], [-0.8165, 0.5774, 0.0]])  # Angstrom
    masses = np.array([15.999, 1.008, 1.008])
    site -= masses @ site / masses.sum()
    u = mda.Universe.empty(3 * n, n_residues=n, atom_resindex=np.repeat(np.arange(n), 3), trajectory=True)
    u.add_TopologyAttr("names", ["O", "H1", "H2"] * n)
    u.add_TopologyAttr("masses", np.tile(masses, n))
    u.add_TopologyAttr("resnames", ["HOH"] * n)
    u.add_TopologyAttr("resids", np.arange(1, n + 1))
    x = (10 * r)[:, :, None, :] + site[None, None]
    u.load_new(x.reshape(len(r), 3 * n, 3).astype(np.float32),
               format=mda.coordinates.memory.MemoryReader, dt=dt)
    return u


@pytest.mark.parametrize("length_ps, dt, window", [(4.0, 0.02, (0.08, 0.4)), (20.0, 0.1, (0.4, 2.0))])
def test_the_error_of_d_is_the_scatter_between_independent_pieces(length_ps, dt, window):
    """Before: SelfDiffusion's error was the molecules' scatter, 2-2.4x below the scatter of D between
    independent pieces of these walks.  Now it comes from 5 blocks of each piece and is that scatter within
    a factor 1.4 (the whole-piece fit uses the origins across the blocks' edges too: the blocks' error is
    ~0.9x the scatter), over 80 pieces of 4 and of 20 ps."""
    assert (FRAMES - 1) * dt == pytest.approx(length_ps, rel=0.01)
    rng = np.random.default_rng(42)
    u = _waters(_walk(rng, N_PIECES * FRAMES, N_WALKERS, dt), dt)
    fits = [SelfDiffusion(u, window).run(start=k * FRAMES, stop=(k + 1) * FRAMES).results for k in range(N_PIECES)]
    D = np.array([f.D for f in fits])
    se = np.array([f.se for f in fits])
    scatter, rms = D.std(ddof=1), np.sqrt(np.mean(se ** 2))
    assert 1 / 1.4 < scatter / rms < 1.4, (scatter, rms)  # 0.94 at 4 ps, 0.87 at 20 ps
    assert all(f.se_note is None and f.n_samples == 5 for f in fits)
    # D is the walkers' own, less the 1/n the common centre's motion takes with it (drift removed)
    assert abs(D.mean() - 1000 * D0 * (1 - 1 / N_WALKERS)) < 3 * scatter / np.sqrt(N_PIECES)
    # the molecules' scatter, the former error, understates it twice over on these walkers
    molecules = [SelfDiffusion(u, window, error="molecules").run(start=k * FRAMES, stop=(k + 1) * FRAMES)
                 .results.se for k in range(0, N_PIECES, 4)]
    assert scatter / np.sqrt(np.mean(np.square(molecules))) > 1.8  # 3.9 at 4 ps, 2.0 at 20 ps


def test_no_error_bar_where_the_window_does_not_fit_the_blocks():
    """A window reaching half the run (the default, T/10 to T/2) leaves one independent stretch of it: D is
    given, its error is not, and the note says why and what would give one.  The kernel refuses by name."""
    rng = np.random.default_rng(7)
    r = _walk(rng, FRAMES, N_WALKERS, 0.02)
    d = SelfDiffusion(_waters(r, 0.02)).run().results
    assert np.isfinite(d.D) and np.isnan(d.se)
    assert d.se_note == ("no error bar: it comes from 5 blocks of the run (3.98 ps: blocks of 0.8 ps), each of which "
                         "must hold the fit window twice, and the window ends at 2 ps; a window ending by 0.4 ps, or "
                         "a run of 20 ps or more, gives one (the molecules' own scatter would understate it 2-3x: a "
                         "liquid's molecules move together)")
    with pytest.raises(ValueError, match="no error bar: .* the window ends at 0.42 ps; a window ending by 0.4 ps"):
        block_error(r, 0.02, (0.1, 0.42))
    with pytest.raises(ValueError, match="n_blocks must be an integer >= 2, got 1"):
        block_error(r, 0.02, (0.1, 0.2), n_blocks=1)
    # the window that fits: the error of the blocks, and the same D as the whole-run fit
    fit = SelfDiffusion(_waters(r, 0.02), (0.08, 0.4)).run().results
    assert fit.se == pytest.approx(block_error(r, 0.02, (0.08, 0.4)), rel=1e-4)
    assert fit.D == pytest.approx(self_diffusion(r, 0.02, (0.08, 0.4)).D, rel=1e-4)
