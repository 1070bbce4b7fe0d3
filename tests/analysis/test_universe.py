"""The MDAnalysis analyses (openmm_symprk.analysis.universe) on trajectories this package did not write: they give
the figures of the package's numpy analyses (openmm_symprk.analysis: diffusion, reorientation, angular, structure;
openmm_symprk.stats for the temperatures) on the same frames kept in memory, as the fidelity study computes them, and
agree with what others wrote on the same frames: MDAnalysis' EinsteinMSD, the waterdynamics MDAKit's
WaterOrientationalRelaxation, transport-analysis' VelocityAutocorr and MDAnalysis' InterRDF."""
import numpy as np
import pytest

mda = pytest.importorskip("MDAnalysis")
from MDAnalysis.coordinates.memory import MemoryReader  # noqa: E402

from openmm_symprk.analysis import angular, diffusion, reorientation, structure  # noqa: E402
from openmm_symprk.analysis.angular import angular_velocities  # noqa: E402
from openmm_symprk.analysis.molecules import centre_of_mass_trajectory  # noqa: E402
from openmm_symprk.analysis.universe import (AngularVelocityCorrelation, KineticTemperatures,  # noqa: E402
                                             RadialDistribution, Reorientation, SelfDiffusion, find_waters)
from openmm_symprk.physics.temperature import kinetic_temperatures  # noqa: E402
from openmm_symprk.stats import series_stats  # noqa: E402

pytestmark = [pytest.mark.filterwarnings("ignore::DeprecationWarning"),
              pytest.mark.filterwarnings("ignore:Reader has no dt"), pytest.mark.filterwarnings("ignore:Found no")]

CFG = {"msd_window_ps": [0.5, 2.5], "tau_fit": [0.1, 0.5], "omega_max_lag_ps": 0.5, "rdf_r_min_nm": 0.2,
       "temperature": 300.0}


def _dcd(plain):
    return mda.Universe(plain.pdb, plain.dcd)


def _in_memory(plain, velocities=True):
    """A Universe of the in-memory float64 frames (continuous positions) with the PDB's topology."""
    u = mda.Universe(plain.pdb)
    dims = np.tile(np.r_[plain.box * 10.0, 90.0, 90.0, 90.0], (len(plain.x), 1))
    u.load_new(plain.x * 10.0, format=MemoryReader, dimensions=dims, dt=plain.dt,
               velocities=plain.v * 10.0 if velocities else None)
    return u


@pytest.fixture(scope="module")
def figures(plain_water):
    """The figures of the package's numpy analyses on the in-memory frames (continuous float64 positions and
    velocities), with the settings of :data:`CFG`: ({name: [value, se]}, {curve name: array})."""
    p = plain_water
    mols, dt = p.molecules, p.dt
    obs, curves = {}, {}
    d = diffusion.self_diffusion(centre_of_mass_trajectory(p.x, p.masses, mols), dt, CFG["msd_window_ps"])
    obs["D"], curves["msd"] = [d.D, d.se], d.msd
    vectors = {"dip": reorientation.dipole_vectors(p.x, mols, p.charges),
               "hh": reorientation.atom_vectors(p.x, mols, 1, 2)}
    for key, u in vectors.items():
        for order in (1, 2):
            c, fit = reorientation.reorientation_time(u, order, dt, c_cut=CFG["tau_fit"][0], c_fit=CFG["tau_fit"][1])
            obs[f"tau{order}_{key}"], curves[f"c{order}_{key}"] = [fit.tau, fit.se], c
    omega = angular_velocities(p.x, p.v, p.masses, mols)
    c, w = angular.omega_correlation(omega, dt, max(2, int(round(CFG["omega_max_lag_ps"] / dt))))
    curves["omega_acf"] = c
    obs.update(w_zero=[1000 * w.t_zero, 1000 * w.t_zero_se], w_min=[w.c_min, w.c_min_se],
               w_int=[1000 * w.integral, 1000 * w.integral_se])
    temps = [kinetic_temperatures(x, v, p.masses, mols.tolist(), True, 3 * len(mols)) for x, v in zip(p.x, p.v)]
    t_trans, t_rot = np.array([[t.translational, t.rotational] for t in temps]).T
    for key, series in (("T_trans", t_trans), ("dT", t_rot - t_trans)):
        s = series_stats(series, dt)
        obs[key] = [s.mean, s.se]
    rdf = structure.radial_distribution(p.x[:, mols[:, 0]], p.box, 0.5 * p.box.min(), n_blocks=5)
    peak = structure.first_peak(rdf, CFG["rdf_r_min_nm"])
    obs.update(g_r=[peak.r, peak.r_se], g_h=[peak.height, peak.height_se])
    curves["g_oo"] = rdf.g
    return obs, curves


def test_finds_the_waters_of_an_openmm_pdb(plain_water):
    w = find_waters(_dcd(plain_water))
    assert w.n_molecules == 64 and w.molecules.shape == (64, 3)
    assert list(w.atoms[w.molecules[0]].names) == ["O", "H1", "H2"]
    np.testing.assert_allclose(w.masses, plain_water.masses, rtol=1e-3)  # the PDB's element masses


def test_self_diffusion_from_the_wrapped_dcd_is_the_study_figure(plain_water, figures):
    """The DCD holds positions wrapped into the box in float32; made whole, unwrapped and fitted they give the
    study's D from the continuous float64 frames (the masses of the PDB's elements move the centres by < 1e-4)."""
    obs, curves = figures
    u = _dcd(plain_water)
    d = SelfDiffusion(u, CFG["msd_window_ps"], masses=plain_water.masses, error="molecules").run()
    assert d.results.D == pytest.approx(obs["D"][0], rel=2e-4)
    assert d.results.se == pytest.approx(obs["D"][1], rel=1e-2)  # the study's (molecules') error
    # MDAnalysis' units and names: the MSD in Angstrom^2 (the study's is nm^2), lags in ps, D's unit stated
    np.testing.assert_allclose(d.results.timeseries, 100.0 * curves["msd"], rtol=1e-3, atol=1e-5)
    assert d.results.msds_by_particle.shape == (len(d.results.timeseries), 64)
    np.testing.assert_allclose(d.results.msds_by_particle.mean(axis=1), d.results.timeseries, rtol=1e-12)
    np.testing.assert_allclose(d.results.lag_ps, np.arange(len(d.results.timeseries)) * plain_water.dt, rtol=1e-6)
    assert d.results.units == {"D": "1e-5 cm^2/s", "se": "1e-5 cm^2/s", "D_infinite": "1e-5 cm^2/s",
                               "correction": "1e-5 cm^2/s", "timeseries": "Angstrom^2",
                               "msds_by_particle": "Angstrom^2", "lag_ps": "ps", "window_ps": "ps"}
    # the molecules cross the box: without unwrapping the MSD would saturate
    assert (plain_water.x[-1, plain_water.molecules[:, 0]] > plain_water.box).any() or d.results.timeseries[-1] > 2


def test_yeh_hummer_correction_is_added_for_a_cubic_box(plain_water):
    from openmm_symprk.analysis.diffusion import yeh_hummer

    d = SelfDiffusion(_dcd(plain_water), CFG["msd_window_ps"], viscosity_mpas=0.729, temperature_k=300.0).run()
    assert d.results.correction == pytest.approx(yeh_hummer(plain_water.box[0], 300.0, 0.729), rel=1e-6)
    assert d.results.D_infinite == pytest.approx(d.results.D + d.results.correction)


def test_reorientation_times_are_the_study_figures(plain_water, figures):
    obs, curves = figures
    r = Reorientation(_dcd(plain_water), c_cut=CFG["tau_fit"][0], c_fit=CFG["tau_fit"][1]).run()
    assert r.results.dipole_from == "bisector"  # a PDB has no charges: SPC/E's dipole lies on the bisector
    for name, key in (("dipole", "dip"), ("HH", "hh")):
        for order in (1, 2):
            tau = r.results.tau[name][f"tau{order}"]
            assert tau.tau == pytest.approx(obs[f"tau{order}_{key}"][0], rel=1e-4), (name, order)
            assert tau.se == pytest.approx(obs[f"tau{order}_{key}"][1], rel=1e-2), (name, order)
            np.testing.assert_allclose(r.results.C[name][f"C{order}"], curves[f"c{order}_{key}"], atol=2e-5)
    assert 0.5 < r.results.tau["OH"]["tau2"].tau < 5.0


def test_angular_velocity_correlation_is_the_study_figure(plain_water, figures):
    obs, curves = figures
    lag = int(round(CFG["omega_max_lag_ps"] / plain_water.dt))
    a = AngularVelocityCorrelation(_in_memory(plain_water), max_lag=lag, masses=plain_water.masses).run()
    s = a.results.summary
    np.testing.assert_allclose(a.results.acf, curves["omega_acf"], atol=1e-5)
    assert 1000 * s.integral == pytest.approx(obs["w_int"][0], rel=1e-4, abs=1e-3)
    assert 1000 * s.t_zero == pytest.approx(obs["w_zero"][0], rel=1e-4)
    assert s.c_min == pytest.approx(obs["w_min"][0], rel=1e-3)


def test_kinetic_temperatures_are_the_study_figures(plain_water, figures):
    obs, _ = figures
    u = _in_memory(plain_water)
    k = KineticTemperatures(u.atoms, masses=plain_water.masses, by="residues", constraints=3 * 64,
                            n_blocks=None).run()
    assert k.results.mean_translational == pytest.approx(obs["T_trans"][0], rel=1e-5)
    assert k.results.se_translational == pytest.approx(obs["T_trans"][1], rel=1e-2)
    assert k.results.mean_difference == pytest.approx(obs["dT"][0], abs=1e-3)
    blocks = KineticTemperatures(u.atoms, masses=plain_water.masses, by="residues").run()
    assert blocks.results.se_translational > 0 and blocks.results.mean_translational == k.results.mean_translational


def test_radial_distribution_is_the_study_figure_and_interrdf(plain_water, figures):
    from MDAnalysis.analysis.rdf import InterRDF

    obs, curves = figures
    u = _dcd(plain_water)
    g = RadialDistribution(u, peak_from=10 * CFG["rdf_r_min_nm"]).run()
    # Angstrom (the study's nm); float32 moves pairs across bin edges, which moved the vertex by 1.5e-4 Angstrom
    # in one run of the (not bitwise reproducible) simulation, where the peak's standard error was 7e-3
    assert g.results.peak.r == pytest.approx(10 * obs["g_r"][0], abs=5e-4)
    assert g.results.peak.r_se == pytest.approx(10 * obs["g_r"][1], rel=1e-2)
    assert g.results.peak.height == pytest.approx(obs["g_h"][0], rel=1e-3)  # float32 moves a few pairs
    np.testing.assert_allclose(g.results.rdf, curves["g_oo"], atol=1e-3)  # a pair moved across a bin edge
    oxygens = u.select_atoms("name O")
    half = 5.0 * plain_water.box.min()  # the default range: half the shortest edge, Angstrom
    ref = InterRDF(oxygens, oxygens, nbins=int(half / 0.05 + 1e-9), range=(0, int(half / 0.05 + 1e-9) * 0.05),
                   exclusion_block=(1, 1)).run()
    np.testing.assert_allclose(g.results.bins, ref.results.bins, rtol=1e-6)  # InterRDF's names and units
    np.testing.assert_allclose(g.results.edges, ref.results.edges, rtol=1e-6)
    np.testing.assert_allclose(g.results.rdf, ref.results.rdf, atol=1e-3)  # float32 in nm and in Angstrom
    assert g.results.units == {"bins": "Angstrom", "edges": "Angstrom", "rdf": "", "rdf_se": "", "peak.r": "Angstrom",
                               "peak.height": ""}
    assert 2.6 < g.results.peak.r < 3.0 and 2.3 < g.results.peak.height < 3.6  # liquid water's first shell


def test_radial_distribution_takes_interrdf_range_and_nbins_in_angstrom(plain_water):
    from MDAnalysis.analysis.rdf import InterRDF

    u = _dcd(plain_water)
    g = RadialDistribution(u, nbins=40, range=(0.0, 6.0), n_blocks=2).run(stop=20)
    oxygens = u.select_atoms("name O")
    ref = InterRDF(oxygens, oxygens, nbins=40, range=(0.0, 6.0), exclusion_block=(1, 1)).run(stop=20)
    np.testing.assert_allclose(g.results.edges, ref.results.edges, rtol=1e-12)
    # the same histogram, up to a pair whose distance lies on a bin edge within float32 round-off (MDAnalysis reads
    # float32 positions): where the two differ, by at most one pair (two counts: InterRDF counts i-j and j-i) moved
    # to a neighbouring bin, in at most two bins (the fixture's trajectory is not the same bit for bit every time)
    diff = np.abs(g.results.rdf - ref.results.rdf)
    moved = np.nonzero(diff > 1e-6)[0]
    one_pair = 2 * ref.results.rdf / np.maximum(ref.results.count, 1)
    assert len(moved) <= 2 and np.all(diff[moved] <= 1.01 * np.maximum(one_pair[moved], 2 * g.results.rdf[moved]
                                                                       / np.maximum(ref.results.count[moved], 1))), \
        (moved, diff[moved], one_pair[moved])
    with pytest.raises(ValueError, match=r"range must be \(0, r_max\) in Angstrom.*got \(1.0, 6.0\)"):
        RadialDistribution(u, range=(1.0, 6.0))
    with pytest.raises(ValueError, match="nbins must be a positive integer, got 0"):
        RadialDistribution(u, nbins=0)
    with pytest.raises(TypeError, match="unexpected keyword argument 'r_max'"):  # the former nm keyword, refused
        RadialDistribution(u, r_max=0.6)


def test_msd_agrees_with_einstein_msd_on_the_centres_of_mass(plain_water):
    """EinsteinMSD (FFT, tidynamics) on a Universe of the molecules' unwrapped centres of mass gives the MSD
    that SelfDiffusion fits (common centre's drift left in, as EinsteinMSD leaves it)."""
    pytest.importorskip("tidynamics")
    from MDAnalysis.analysis.msd import EinsteinMSD

    p = plain_water
    d = SelfDiffusion(_dcd(p), CFG["msd_window_ps"], drift=False, masses=p.masses).run()
    com = centre_of_mass_trajectory(p.x, p.masses, p.molecules)  # continuous already
    u = mda.Universe.empty(len(p.molecules), trajectory=False)
    u.load_new(com * 10.0, format=MemoryReader)
    ref = EinsteinMSD(u.atoms, msd_type="xyz", fft=True).run()
    lags = len(d.results.timeseries)
    np.testing.assert_allclose(d.results.timeseries, ref.results.timeseries[:lags], rtol=1e-3, atol=1e-5)
    np.testing.assert_allclose(d.results.msds_by_particle, ref.results.msds_by_particle[:lags], rtol=1e-3, atol=1e-4)


@pytest.mark.parametrize("order", [1, 2])
def test_reorientation_agrees_with_waterdynamics(plain_water, order):
    """WaterOrientationalRelaxation averages each lag dt over the origins 0, dt, 2 dt ... only; on the frames
    taken every dt our correlation at lag 1 averages the same origins, and gives its numbers (OH: O->H1, HH,
    dipole: the bisector).  Over all origins (ours) the curves agree within the noise of its few origins."""
    wd = pytest.importorskip("waterdynamics")
    u = _dcd(plain_water)
    n_frames, dtmax = 100, 4
    ref = wd.WaterOrientationalRelaxation(u, "byres name O", 0, n_frames, dtmax, order=order)
    ref.run()
    oh, hh, dip = (np.array(c) for c in zip(*ref.timeseries))
    x = u.trajectory.timeseries(u.atoms, order="fac")[:n_frames].astype(np.float64) * 0.1
    mols = find_waters(u).atoms.indices.reshape(-1, 3)
    box = u.dimensions[:3] * 0.1
    ours = {"OH": reorientation.atom_vectors(x, mols, 0, 1, box), "HH": reorientation.atom_vectors(x, mols, 1, 2, box),
            "dipole": reorientation.bisector_vectors(x, mols, box=box)}
    for name, theirs in (("OH", oh), ("HH", hh), ("dipole", dip)):
        for dt in range(1, dtmax + 1):
            frames = ours[name][:(n_frames // dt) * dt:dt]
            c = reorientation.legendre_correlation(frames, order, max_lag=1).mean(axis=1)[1]
            assert c == pytest.approx(theirs[dt - 1], abs=2e-5), (name, dt)
    full = Reorientation(u, vectors=("HH",), orders=(order,)).run(stop=n_frames)  # the frames compared above
    # its lag dt averages n_frames / dt origins of 64 waters (25 at dt = 4): agreement within that noise
    np.testing.assert_allclose(full.results.C["HH"][f"C{order}"][1:dtmax + 1], hh, atol=0.05)


def test_angular_velocity_acf_agrees_with_transport_analysis(plain_water):
    """transport-analysis' VelocityAutocorr (FFT, tidynamics) of the molecules' angular velocities, given to it
    as the velocities of one particle per molecule, normalised by its lag 0: our autocorrelation."""
    pytest.importorskip("transport_analysis")
    from transport_analysis.velocityautocorr import VelocityAutocorr

    p = plain_water
    a = AngularVelocityCorrelation(_in_memory(p), max_lag=50, masses=p.masses).run()
    omega = a.results.omega
    u = mda.Universe.empty(omega.shape[1], trajectory=False)
    u.load_new(np.zeros_like(omega), format=MemoryReader, velocities=omega, dt=p.dt)
    ref = VelocityAutocorr(u.atoms, fft=True).run().results.timeseries
    np.testing.assert_allclose(a.results.acf, ref[:51] / ref[0], atol=1e-6)


def test_velocity_autocorrelation_of_an_amber_file_agrees_with_transport_analysis():
    """A trajectory from the MDAnalysis test files (AMBER NetCDF with velocities, 464 TIP3P waters): the
    package's origin-averaged correlation of the atoms' velocities is transport-analysis' VACF."""
    pytest.importorskip("transport_analysis")
    datafiles = pytest.importorskip("MDAnalysisTests.datafiles")
    from transport_analysis.velocityautocorr import VelocityAutocorr

    from openmm_symprk.analysis.correlation import origin_averaged_correlation

    u = mda.Universe(datafiles.PRM_NCBOX, datafiles.TRJ_NCBOX)
    water = u.select_atoms("resname WAT")
    ref = VelocityAutocorr(water, fft=True).run().results.timeseries
    v = np.array([water.velocities.astype(np.float64) for _ in u.trajectory])
    ours = origin_averaged_correlation(v, max_lag=len(v) - 1).sum(axis=2).mean(axis=1)
    np.testing.assert_allclose(ours, ref, rtol=1e-5)
    k = KineticTemperatures(water, by="residues").run()
    assert 250 < k.results.mean_translational < 350 and 250 < k.results.mean_rotational < 350
    assert k.results.se_translational > 0


def test_no_water_and_no_velocities_are_clear_errors(plain_water):
    datafiles = pytest.importorskip("MDAnalysisTests.datafiles")
    protein = mda.Universe(datafiles.PSF, datafiles.DCD)  # adenylate kinase in vacuum
    with pytest.raises(ValueError, match="no water in the selection"):
        SelfDiffusion(protein)
    with pytest.raises(ValueError, match="needs velocities.*DCD"):
        AngularVelocityCorrelation(_dcd(plain_water)).run(stop=3)
    with pytest.raises(ValueError, match="needs velocities"):
        KineticTemperatures(_dcd(plain_water).atoms, by="residues").run(stop=3)
    with pytest.raises(ValueError, match="vectors must be among"):
        Reorientation(_dcd(plain_water), vectors=("NH",))


def test_unevenly_spaced_frames_are_refused(plain_water):
    u = _dcd(plain_water)
    r = Reorientation(u, vectors=("HH",), orders=(1,))
    with pytest.raises(ValueError, match="not evenly spaced"):
        r.run(frames=[0, 1, 2, 4, 5, 6, 7, 8, 9, 10, 11, 12])


@pytest.mark.parametrize("cls", [SelfDiffusion, Reorientation, AngularVelocityCorrelation, RadialDistribution,
                                 KineticTemperatures])
def test_frame_range_and_misspelt_keywords_are_refused(plain_water, cls):
    """MDAnalysis' AnalysisBase takes **kwargs and ignores them: stop= given to a constructor would analyse every
    frame without a word.  The classes refuse what they do not take, and say where the frame range goes."""
    u = _dcd(plain_water)
    by = {"by": "residues"} if cls is KineticTemperatures else {}  # the PDB has no bonds
    with pytest.raises(TypeError, match=r"unexpected keyword argument 'stop'.*frames to analyse.*\.run\(\)"):
        cls(u, stop=10, **by)
    with pytest.raises(TypeError, match=r"unexpected keyword argument 'n_block'.*it takes .*'verbose'"):
        cls(u, n_block=3, **by)
    assert cls(u, verbose=True, **by)._verbose is True
