"""ConservationReporter and VelocityTRRReporter in an app.Simulation."""
import io

import numpy as np
import openmm as mm
import openmm.app as app
import openmm.unit as unit
import pytest

from openmm_symprk import SymplecticIntegrator
from openmm_symprk.conservation.reporters import ConservationReporter, VelocityTRRReporter, write_topology
from openmm_symprk.systems.checks import ConservationWarning


def _simulation(scene, system=None, integrator=None):
    system = system or scene.system
    integrator = integrator or SymplecticIntegrator(0.002, "verlet", system=scene.system)
    sim = app.Simulation(scene.topology, system, integrator, mm.Platform.getPlatformByName("Reference"))
    sim.context.setPositions(scene.positions)
    sim.context.setVelocities(scene.velocities)
    return sim


def test_describe_next_report_is_dict(water8, tmp_path):
    """OpenMM 8.6 Simulation takes the dict form {'steps', 'periodic', 'include'}."""
    sim = _simulation(water8)
    for rep in (ConservationReporter(io.StringIO(), 30), VelocityTRRReporter(str(tmp_path / "d.trr"), 30)):
        d = rep.describeNextReport(sim)
        assert d["steps"] == 30 and d["periodic"] is False
        assert {"positions", "velocities"} <= set(d["include"])


def test_conservation_reporter_output_parses(water8, tmp_path):
    path = tmp_path / "cons.csv"
    sim = _simulation(water8)
    rep = ConservationReporter(str(path), 50)
    sim.reporters.append(rep)
    sim.step(200)
    rep.close()
    text = path.read_text().splitlines()
    assert text[0].startswith('#"Step"') and len(text[0].split(",")) == 9
    data = np.loadtxt(path, delimiter=",", comments="#")
    assert data.shape == (4, 9)
    assert list(data[:, 0]) == [50, 100, 150, 200]
    assert np.allclose(data[:, 1], [0.1, 0.2, 0.3, 0.4])
    assert np.isnan(data[0, 3]) and np.all(np.isfinite(data[1:, 3]))
    assert np.all(data[:, 4] < 1e-10)  # |dP|, Reference
    assert np.all(data[:, 5] < 1e-12)  # |dL|/|L|, Reference
    assert np.all(data[:, 6] < 1e-6)  # constraint error
    # kinetic temperatures of the 8 spinning waters (150 K Maxwell-Boltzmann plus a spin): finite, positive,
    # and equal to the package's own function on the final state
    from openmm_symprk.conservation import kinetic_temperatures

    t = kinetic_temperatures(sim.context)
    assert np.all(data[:, 7:9] > 0) and data[-1, 7] == pytest.approx(t.translational, rel=1e-4)
    assert data[-1, 8] == pytest.approx(t.rotational, rel=1e-4)
    assert rep.records[-1]["dL_rel"] == pytest.approx(data[-1, 5], rel=1e-3)


def test_conservation_reporter_stdout(water8, capsys):
    sim = _simulation(water8)
    sim.reporters.append(ConservationReporter(None, 10))
    sim.step(20)
    out = capsys.readouterr().out.splitlines()
    assert out[0].startswith("#") and len(out) == 3


def test_warns_once_with_reason(water8, monkeypatch):
    system = mm.XmlSerializer.clone(water8.system)
    system.addForce(mm.CMMotionRemover())
    with pytest.warns(ConservationWarning) as rec:
        for _ in range(2):
            sim = _simulation(water8, system=system,
                              integrator=mm.LangevinMiddleIntegrator(150, 1.0, 0.002))
            rep = ConservationReporter(io.StringIO(), 10)
            sim.reporters.append(rep)
            sim.step(20)
            assert {k for k, _ in rep.issues} == {"cmmotionremover", "langevinmiddleintegrator"}
    msgs = [str(w.message) for w in rec if issubclass(w.category, ConservationWarning)]
    assert sum("CMMotionRemover" in m for m in msgs) == 1, msgs
    assert sum("heat bath" in m for m in msgs) == 1, msgs
    assert all(m.startswith("ConservationReporter:") for m in msgs)


@pytest.mark.filterwarnings("ignore:Reload offsets")
def test_trr_reporter_round_trip(water8, tmp_path):
    import MDAnalysis as mda

    trr, pdb = str(tmp_path / "t.trr"), str(tmp_path / "t.pdb")
    sim = _simulation(water8)
    rep = VelocityTRRReporter(trr, 25)
    sim.reporters.append(rep)
    sim.step(100)
    rep.close()
    write_topology(pdb, water8.topology, water8.positions)
    st = sim.context.getState(getPositions=True, getVelocities=True)
    u = mda.Universe(pdb, trr)
    assert len(u.trajectory) == 4
    ts = u.trajectory[-1]
    assert ts.has_velocities and ts.data["step"] == 100 and ts.time == pytest.approx(0.2, rel=1e-6)
    x = st.getPositions(asNumpy=True)._value * 10
    v = st.getVelocities(asNumpy=True)._value * 10
    assert np.allclose(ts.positions, x, rtol=1e-6, atol=1e-5)  # float32
    assert np.allclose(ts.velocities, v, rtol=1e-6, atol=1e-5)
    # append continues after the old frames without rewriting them: the first bytes are untouched
    before = open(trr, "rb").read()
    rep2 = VelocityTRRReporter(trr, 25, append=True)
    assert rep2.frames == 4
    sim.reporters[0] = rep2
    sim.step(50)
    rep2.close()
    assert open(trr, "rb").read().startswith(before)
    assert len(mda.Universe(pdb, trr).trajectory) == 6


_READER = """
import sys, warnings
warnings.simplefilter("ignore")
from openmm_symprk.conservation.analysis import AngularMomentum
import MDAnalysis as mda
u = mda.Universe(sys.argv[1], sys.argv[2])
L = AngularMomentum(u.atoms).run()
print(len(u.trajectory), u.trajectory[-1].data["step"], float(abs(L.results.relative_drift).max()))
"""


def test_trr_is_readable_by_another_process_after_every_report(water8, tmp_path):
    """No close(), no garbage collection: after each report the file on disk holds every frame so far."""
    import subprocess
    import sys

    trr, pdb = str(tmp_path / "live.trr"), str(tmp_path / "live.pdb")
    write_topology(pdb, water8.topology, water8.positions)
    sim = _simulation(water8)
    sim.reporters.append(VelocityTRRReporter(trr, 10))
    for n in (1, 3):
        sim.step(10 * n - sim.currentStep)
        res = subprocess.run([sys.executable, "-c", _READER, pdb, trr], capture_output=True, text=True, timeout=120)
        assert res.returncode == 0, res.stderr[-2000:]
        frames, step, drift = res.stdout.split()
        assert int(frames) == n and int(step) == 10 * n
        assert float(drift) < 1e-5  # the float32 floor of a stored trajectory, not a broken frame


@pytest.mark.parametrize("interval", [2.5, 0, -3, True, "10", 2.0])
def test_report_intervals_must_be_positive_whole_numbers(interval, tmp_path):
    """2.5 used to be truncated to 2 in silence; now every reporter says what it takes."""
    for make in (lambda: ConservationReporter(io.StringIO(), interval),
                 lambda: VelocityTRRReporter(str(tmp_path / "i.trr"), interval)):
        with pytest.raises(ValueError, match=f"positive whole number of steps.*got {interval!r}"):
            make()
    assert ConservationReporter(io.StringIO(), np.int64(5))._interval == 5


def test_drift_column_is_the_least_squares_slope_of_every_report(water8):
    """The running fit (constant work per report) gives what a fit of the whole history gives."""
    from openmm_symprk.stats import drift

    sim = _simulation(water8)
    rep = ConservationReporter(io.StringIO(), 5)
    sim.reporters.append(rep)
    sim.step(100)
    t = np.array([r["time"] for r in rep.records])
    e = np.array([r["total_energy"] for r in rep.records])
    dof = water8.n_dof
    for k in (3, 10, 20):
        assert rep.records[k - 1]["energy_drift"] == pytest.approx(drift(t[:k], e[:k]).slope * 1000 / dof, rel=1e-6)


def _tip4p_waters(n=3, seed=4):
    """``n`` rigid TIP4P-Ew waters in vacuum (each with a ThreeParticleAverageSite M), spun up."""
    from openmm_symprk.systems.prepare import maxwell_boltzmann
    from openmm_symprk.systems.scenes import water_cluster

    base = water_cluster(n, rigid=True, minimize=False)
    ff = app.ForceField("tip4pew.xml")
    mod = app.Modeller(base.topology, base.positions * unit.nanometer)
    mod.addExtraParticles(ff)
    system = ff.createSystem(mod.topology, nonbondedMethod=app.NoCutoff, rigidWater=True, removeCMMotion=False)
    x = np.array(mod.positions.value_in_unit(unit.nanometer))
    v = maxwell_boltzmann(system, x, 300.0, seed, (0.0, 0.0, 3.0))
    return system, mod.topology, x, v


def test_trr_has_the_velocities_virtual_sites_move_with(tmp_path):
    """TIP4P-Ew: OpenMM's State gives the M site zero velocity; the trajectory has w1 v_O + w2 v_H1 + w3 v_H2, and
    it is the site's actual motion (a central difference of its written positions over two steps)."""
    from MDAnalysis.lib.formats.libmdaxdr import TRRFile

    system, top, x, v = _tip4p_waters()
    sites = [i for i in range(system.getNumParticles()) if system.isVirtualSite(i)]
    assert len(sites) == 3
    dt = 0.0002
    sim = app.Simulation(top, system, mm.VerletIntegrator(dt), mm.Platform.getPlatformByName("Reference"))
    sim.context.setPositions(x)
    sim.context.setVelocities(v)
    sim.context.computeVirtualSites()
    path = tmp_path / "tip4p.trr"
    rep = VelocityTRRReporter(str(path), 1)
    sim.reporters.append(rep)
    sim.step(3)
    rep.close()
    assert not np.any(sim.context.getState(getVelocities=True).getVelocities(asNumpy=True)[sites[0]]._value)
    with TRRFile(str(path), "r") as f:
        frames = [(fr.x.astype(float), fr.v.astype(float)) for fr in f]  # the XDR library: nm and nm/ps, as written
    for s in sites:
        vs = system.getVirtualSite(s)
        xs, vv = frames[1]
        expected = sum(vs.getWeight(k) * vv[vs.getParticle(k)] for k in range(3))
        assert np.linalg.norm(vv[s]) > 0.1
        assert np.allclose(vv[s], expected, rtol=1e-5, atol=1e-5)
        moved = (frames[2][0][s] - frames[0][0][s]) / (2 * dt)
        assert np.allclose(vv[s], moved, rtol=2e-2, atol=2e-2), (vv[s], moved)


@pytest.mark.parametrize("kind", ["out-of-plane", "local-coordinates"])
def test_nonlinear_virtual_sites_move_as_their_position_function_says(kind):
    """OutOfPlaneSite (bilinear cross term) and LocalCoordinatesSite (a rotated offset): the computed velocity is
    the derivative of OpenMM's own site placement along the parents' velocities."""
    from openmm_symprk.systems.virtual_sites import VirtualSiteVelocities

    system = mm.System()
    for m in (16.0, 1.0, 1.0, 0.0):
        system.addParticle(m)
    if kind == "out-of-plane":
        system.setVirtualSite(3, mm.OutOfPlaneSite(0, 1, 2, 0.3, 0.4, 6.0))
    else:
        system.setVirtualSite(3, mm.LocalCoordinatesSite([0, 1, 2], [0.6, 0.2, 0.2], [-1.0, 1.0, 0.0],
                                                         [-1.0, 0.0, 1.0], mm.Vec3(0.03, 0.05, -0.04)))
    rng = np.random.default_rng(9)
    x = np.array([[0.0, 0.0, 0.0], [0.0957, 0.0, 0.0], [-0.024, 0.0927, 0.0], [0.0, 0.0, 0.0]])
    v = np.vstack([rng.normal(size=(3, 3)), np.zeros((1, 3))])
    ctx = mm.Context(system, mm.VerletIntegrator(0.001), mm.Platform.getPlatformByName("Reference"))

    def placed(xp):
        ctx.setPositions(np.vstack([xp, np.zeros((1, 3))]))
        ctx.computeVirtualSites()
        return np.array(ctx.getState(getPositions=True).getPositions(asNumpy=True)._value[3])

    h = 1e-7
    expected = (placed(x[:3] + h * v[:3]) - placed(x[:3] - h * v[:3])) / (2 * h)
    got = VirtualSiteVelocities(system)(np.vstack([x[:3], placed(x[:3])]), v)[3]
    assert np.linalg.norm(expected) > 0.1 and np.allclose(got, expected, rtol=1e-5, atol=1e-6), (got, expected)
